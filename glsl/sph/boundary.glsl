// The solid boundary in the densities and pressures of every solver (src/sim/sph/boundary.rs
// has the same in f64): the domain's walls and the colliders, each a solid half-space at
// rest density, the continuum limit of boundary particles (Akinci et al. 2012) as a volume
// map (Koschier & Bender 2017) in closed form. Planes and the box are exact; spheres and
// capsules use the tangent plane at the nearest surface point (exact as radius / h grows);
// one thinner than h, where that plane would count several times its volume, acts by the
// collision response alone. Of the colliders only the nearest surface counts; it and the
// box's walls are united below.
// At a distance d < h from the surface: density / rho0 solid_density(d), the kernel's
// integral over the half-space, and sum V grad W = -solid_push(d) n, n the surface normal
// into the fluid (kernel.glsl).
// A particle inside a solid (the response pushes it out at the step's end) counts d = 0.
#ifndef SPH_BOUNDARY_GLSL
#define SPH_BOUNDARY_GLSL
#include "kernel.glsl"

// The boundary's density / rho0 at x; g: its sum V grad W; rate: its sum V (v - v_b) . grad W
// for a particle moving with v (v_b: the collider's velocity; the box stands still).
// The solids (the box's six walls and the nearest collider surface) overlap at edges and
// corners, where a sum counts the shared solid twice or three times (9.5% of rho0 at a
// corner particle). Their union is taken as 1 - prod(1 - I_k): exact for a separable
// kernel, within 0.4% of rho0 of the numerically integrated union at a cubic corner
// particle; its gradient gives wall k the push A_k prod_{j != k} (1 - I_j).
float boundary(vec3 x, vec3 v, out vec3 g, out float rate) {
    // Each near surface: its normal into the fluid, I, A, its velocity.
    vec3 n[7];
    vec2 ia[7];
    vec3 vb[7];
    uint count = 0u;
    float keep = 1.0;  // prod (1 - I_k)
    float reach = P.h - P.wall_offset;  // the terms vanish past it
    for (int k = 0; k < 3; ++k) {
        vec3 e = vec3(0.0);
        e[k] = 1.0;
        float lo = x[k] - P.domain_min[k], hi = P.domain_max[k] - x[k];
        if (lo < reach) { n[count] = e; vb[count] = vec3(0.0); ia[count++] = vec2(solid_density(lo), solid_push(lo)); }
        if (hi < reach) { n[count] = -e; vb[count] = vec3(0.0); ia[count++] = vec2(solid_density(hi), solid_push(hi)); }
    }
    // Colliders overlap (a character's capsules at its joints): only the nearest surface
    // counts, where a sum would count the shared solid several times over.
    vec3 bn = vec3(0.0), bv = vec3(0.0);
    float bd = reach;
    for (uint c = 0u; c < P.colliders; ++c) {
        Collider col = cols[c];
        if (uint(col.b.w) != 0u && col.a.w < P.h) continue;
        vec3 cn;
        float d = collider_distance(col, x, cn);
        if (d < bd) {
            bd = d;
            bn = cn;
            bv = col.vel.xyz;
        }
    }
    if (bd < reach) { n[count] = bn; vb[count] = bv; ia[count++] = vec2(solid_density(bd), solid_push(bd)); }
    for (uint k = 0u; k < count; ++k) keep *= 1.0 - ia[k].x;
    g = vec3(0.0);
    rate = 0.0;
    for (uint k = 0u; k < count; ++k) {
        float a = ia[k].y * keep / (1.0 - ia[k].x);  // 1 - I >= 1/2
        g -= a * n[k];
        rate -= a * dot(v - vb[k], n[k]);
    }
    return 1.0 - keep;
}
#endif
