// 30-bit Morton codes: 10 bits per axis, x in the highest of each bit triple.
#ifndef PRIMITIVES_MORTON_GLSL
#define PRIMITIVES_MORTON_GLSL
uint morton_expand(uint v) {  // 10 bits -> every third bit
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}
uint morton_code(uvec3 q) {
    return (morton_expand(q.x) << 2) | (morton_expand(q.y) << 1) | morton_expand(q.z);
}
// Quantise p into the 1024^3 lattice of the box [lo, hi] (clamped, so monotone everywhere).
uvec3 morton_cell(vec3 p, vec3 lo, vec3 hi) {
    vec3 t = (p - lo) / max(hi - lo, vec3(1e-30)) * 1024.0;
    return uvec3(clamp(t, vec3(0.0), vec3(1023.0)));
}
#endif
