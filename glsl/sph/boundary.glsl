// The solid boundary in the densities and pressures of every solver (src/sph/boundary.rs
// has the same in f64): the domain's walls and the colliders, each a solid half-space at
// rest density, the continuum limit of boundary particles (Akinci et al. 2012) as a volume
// map (Koschier & Bender 2017) in closed form. Planes and the box are exact; spheres and
// capsules use the tangent plane at the nearest surface point (exact as radius / h grows);
// one thinner than h, where that plane would count several times its volume, acts by the
// collision response alone. The box's walls add up (at an edge or corner the solid they
// share is counted twice: measured harmless in a resting pool); of the colliders only
// the nearest surface counts.
// At a distance d < h from the surface, with u = d / h:
//   density / rho0   I(u) = 1/2 - 315/256 (u - 4/3 u^3 + 6/5 u^5 - 4/7 u^7 + u^9 / 9)
//                    (the poly6 integral over the half-space, as the densities);
//   sum V grad W     -A(u) n, A(u) = 30 / h (w^4 / 4 - w^5 / 5), w = 1 - u
//                    (spiky's, as the gradients), n the surface normal into the fluid.
// A particle inside a solid (the response pushes it out at the step's end) counts d = 0.
#ifndef SPH_BOUNDARY_GLSL
#define SPH_BOUNDARY_GLSL
float solid_density(float d) {
    float u = clamp(d / P.h, 0.0, 1.0), u2 = u * u;
    float f = u * (1.0 + u2 * (-4.0 / 3.0 + u2 * (6.0 / 5.0 + u2 * (-4.0 / 7.0 + u2 / 9.0))));
    return 0.5 - 315.0 / 256.0 * f;
}
float solid_push(float d) {
    float w = 1.0 - clamp(d / P.h, 0.0, 1.0), w4 = w * w * w * w;
    return 30.0 / P.h * (w4 / 4.0 - w4 * w / 5.0);
}

// The boundary's density / rho0 at x; g: its sum V grad W; rate: its sum V (v - v_b) . grad W
// for a particle moving with v (v_b: the collider's velocity; the box stands still).
float boundary(vec3 x, vec3 v, out vec3 g, out float rate) {
    float rho = 0.0;
    g = vec3(0.0);
    rate = 0.0;
    for (int k = 0; k < 3; ++k) {
        float lo = x[k] - P.domain_min[k], hi = P.domain_max[k] - x[k];
        if (lo < P.h) { float a = solid_push(lo); rho += solid_density(lo); g[k] -= a; rate -= a * v[k]; }
        if (hi < P.h) { float a = solid_push(hi); rho += solid_density(hi); g[k] += a; rate += a * v[k]; }
    }
    // Colliders overlap (a character's capsules at its joints): only the nearest surface
    // counts, where a sum would count the shared solid several times over.
    vec3 bn = vec3(0.0), bv = vec3(0.0);
    float bd = P.h;
    for (uint c = 0u; c < P.colliders; ++c) {
        Collider col = cols[c];
        if (uint(col.b.w) != 0u && col.a.w < P.h) continue;
        vec3 n;
        float d = collider_distance(col, x, n);
        if (d < bd) {
            bd = d;
            bn = n;
            bv = col.vel.xyz;
        }
    }
    if (bd < P.h) {
        float a = solid_push(bd);
        rho += solid_density(bd);
        g -= a * bn;
        rate -= a * dot(v - bv, bn);
    }
    return rho;
}
#endif
