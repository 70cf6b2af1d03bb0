// 3D gradient noise (Perlin's improved interpolant on hashed gradients) and the curl of a
// vector potential made of three offset copies: a divergence-free flow field (Bridson
// et al. 2007, curl noise).
#ifndef PSYS_NOISE_GLSL
#define PSYS_NOISE_GLSL
vec3 grad3(ivec3 c) {
    uint h = pcg(uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u);
    vec3 g = vec3(h & 1023u, (h >> 10) & 1023u, (h >> 20) & 1023u) / 511.5 - 1.0;
    return g;
}
float gnoise(vec3 p) {
    ivec3 i = ivec3(floor(p));
    vec3 f = p - floor(p);
    vec3 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float n000 = dot(grad3(i), f);
    float n100 = dot(grad3(i + ivec3(1, 0, 0)), f - vec3(1, 0, 0));
    float n010 = dot(grad3(i + ivec3(0, 1, 0)), f - vec3(0, 1, 0));
    float n110 = dot(grad3(i + ivec3(1, 1, 0)), f - vec3(1, 1, 0));
    float n001 = dot(grad3(i + ivec3(0, 0, 1)), f - vec3(0, 0, 1));
    float n101 = dot(grad3(i + ivec3(1, 0, 1)), f - vec3(1, 0, 1));
    float n011 = dot(grad3(i + ivec3(0, 1, 1)), f - vec3(0, 1, 1));
    float n111 = dot(grad3(i + ivec3(1, 1, 1)), f - vec3(1, 1, 1));
    return mix(mix(mix(n000, n100, u.x), mix(n010, n110, u.x), u.y),
               mix(mix(n001, n101, u.x), mix(n011, n111, u.x), u.y), u.z);
}
vec3 potential(vec3 p) {
    return vec3(gnoise(p), gnoise(p + vec3(31.4, 47.2, 12.9)), gnoise(p + vec3(-19.1, 3.7, 71.3)));
}
// curl(psi) by central differences.
vec3 curl_noise(vec3 p) {
    const float e = 1e-2;
    vec3 dx = (potential(p + vec3(e, 0, 0)) - potential(p - vec3(e, 0, 0))) / (2.0 * e);
    vec3 dy = (potential(p + vec3(0, e, 0)) - potential(p - vec3(0, e, 0))) / (2.0 * e);
    vec3 dz = (potential(p + vec3(0, 0, e)) - potential(p - vec3(0, 0, e))) / (2.0 * e);
    return vec3(dy.z - dz.y, dz.x - dx.z, dx.y - dy.x);
}
#endif
