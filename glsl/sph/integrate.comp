#version 450
// Leapfrog (Kelager 2006): v(t+dt/2) = v(t-dt/2) + a dt, x += v(t+dt/2) dt,
// v(t) = average of the half steps; then collision response against colliders and the
// domain box (velocity split into normal and tangential parts, restitution and friction),
// and a final clamp: no particle ever leaves the domain.
#include "common.glsl"

// Reflect the velocity's normal part (n points into the fluid side), damp the tangent.
vec3 respond(vec3 v, vec3 n, vec3 wall_v) {
    vec3 rel = v - wall_v;
    float vn = dot(rel, n);
    if (vn >= 0.0) return v;
    vec3 vt = rel - vn * n;
    return wall_v + vt * (1.0 - P.domain_max.w) - P.domain_min.w * vn * n;
}

void main() {
    uint i = global_id();
    if (i >= sph_live() || pos[i].w < 0.0) return;  // past the live, or dead
    float dt = P.gravity.w;
    vec3 a = acc[i].xyz;
    vec3 vh_old = vhalf[i].xyz;
    vec3 vh = vh_old + a * dt;
    vec3 x = pos[i].xyz + vh * dt;
    vec3 v = 0.5 * (vh_old + vh);
    for (uint c = 0u; c < P.colliders; ++c) {
        Collider col = cols[c];
        uint kind = uint(col.b.w);
        vec3 n;
        float depth;
        if (kind == 0u) {
            n = col.a.xyz;
            depth = col.a.w - dot(n, x);
        } else {
            vec3 q = col.a.xyz;
            if (kind == 2u) {
                vec3 ab = col.b.xyz - col.a.xyz;
                float t = clamp(dot(x - col.a.xyz, ab) / max(dot(ab, ab), 1e-20), 0.0, 1.0);
                q = col.a.xyz + t * ab;
            }
            vec3 d = x - q;
            float len = length(d);
            n = len > 1e-12 ? d / len : vec3(0.0, 1.0, 0.0);
            depth = col.a.w - len;
        }
        if (depth > 0.0) {
            x += depth * n;
            vh = respond(vh, n, col.vel.xyz);
            v = respond(v, n, col.vel.xyz);
        }
    }
    for (int k = 0; k < 3; ++k) {
        vec3 n = vec3(0.0);
        n[k] = 1.0;
        if (x[k] < P.domain_min[k]) { x[k] = P.domain_min[k]; vh = respond(vh, n, vec3(0.0)); v = respond(v, n, vec3(0.0)); }
        if (x[k] > P.domain_max[k]) { x[k] = P.domain_max[k]; vh = respond(vh, -n, vec3(0.0)); v = respond(v, -n, vec3(0.0)); }
    }
    pos[i].xyz = clamp(x, P.domain_min.xyz, P.domain_max.xyz);
    vhalf[i].xyz = vh;
    vel[i].xyz = v;
}
