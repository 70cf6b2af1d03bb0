// Colliders (SystemParams.colliders): the update's collisions, the boids' avoidance.
#ifndef PSYS_COLLIDE_GLSL
#define PSYS_COLLIDE_GLSL
#include "common.glsl"
// One of the scene character's posed capsules (e0: end 0 and radius, e1: end 1), with
// the response of its collider `col` (kind C_CHARACTER).
Collider posed_capsule(Collider col, vec4 e0, vec4 e1) {
    col.a = vec4(e0.xyz, float(C_CAPSULE));
    col.b = vec4(e1.xyz, e0.w);
    return col;
}
// Push p out of (or back into) collider k; true on contact, with the surface normal.
bool contact(Collider k, inout vec3 p, out vec3 n) {
    uint kind = uint(k.a.w);
    bool inside = k.c.z > 0.5;
    n = vec3(0.0);
    if (kind == C_PLANE) {
        n = normalize(k.a.xyz);
        float s = dot(n, p) - k.b.x;
        if (s >= 0.0) return false;
        p -= s * n;
        return true;
    }
    if (kind == C_SPHERE || kind == C_CAPSULE) {
        vec3 centre = k.a.xyz;
        float r = k.b.x;
        if (kind == C_CAPSULE) {
            vec3 ab = k.b.xyz - k.a.xyz;
            float h = clamp(dot(p - k.a.xyz, ab) / max(dot(ab, ab), 1e-12), 0.0, 1.0);
            centre = k.a.xyz + h * ab;
            r = k.b.w;
        }
        vec3 d = p - centre;
        float l = length(d);
        vec3 dir = l > 1e-9 ? d / l : vec3(0, 1, 0);
        if (!inside && l < r) { n = dir; p = centre + dir * r; return true; }
        if (inside && l > r) { n = -dir; p = centre + dir * r; return true; }
        return false;
    }
    if (kind == C_BOX) {
        vec3 lo = k.a.xyz, hi = k.b.xyz;
        if (inside) {
            vec3 q = clamp(p, lo, hi);
            if (q == p) return false;
            n = normalize(q - p);
            p = q;
            return true;
        }
        if (any(lessThan(p, lo)) || any(greaterThan(p, hi))) return false;
        // Out through the nearest face.
        vec3 dlo = p - lo, dhi = hi - p;
        float best = 1e30;
        for (int ax = 0; ax < 3; ax++) {
            if (dlo[ax] < best) { best = dlo[ax]; n = vec3(0.0); n[ax] = -1.0; }
            if (dhi[ax] < best) { best = dhi[ax]; n = vec3(0.0); n[ax] = 1.0; }
        }
        p += n * best;
        return true;
    }
    return false;
}
#endif
