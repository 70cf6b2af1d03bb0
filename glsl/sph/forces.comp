#version 450
// Forces: pressure (the kernel's gradient, kernel.glsl; symmetric; the solid boundary's, boundary.glsl),
// viscosity (viscosity Laplacian), surface tension (colour field, where |n| >= threshold),
// gravity; writes the acceleration f / rho.
#ifdef PASS
// DFSPH's forces pass (src/sim/sph/pressure.rs): neighbours from the step's lists.
#include "pressure.glsl"
#else
#include "common.glsl"
#define FOR_NEIGHBORS(I, XI, VISIT) { NB_BEGIN(XI, P.h, nl_j) VISIT(nl_j) NB_END }
#endif
void main() {
    uint i = global_id();
    if (i >= sph_live() || pos[i].w < 0.0) return;  // past the live, or dead
    vec3 xi = pos[i].xyz;
    vec3 vi = vel[i].xyz;
    float rho_i = rho_p[i].x, p_i = rho_p[i].y;
    float h = P.h, h2 = h * h;
    vec3 f_press = vec3(0.0), f_visc = vec3(0.0), n = vec3(0.0);
    // Colour-field Laplacian, self term included: lap W_poly6(0) = poly6_grad * h^2 * 3h^2.
    float lap = P.mass / rho_i * P.poly6_grad * h2 * 3.0 * h2;
#define VISIT(j) { \
        vec3 d = xi - pos[j].xyz; \
        float r2 = dot(d, d); \
        if (j != i && r2 < h2) { \
            vec2 rp = rho_p[j]; \
            float vol = P.mass / rp.x; \
            float q = h2 - r2; \
            n += vol * P.poly6_grad * q * q * d; \
            lap += vol * P.poly6_grad * q * (3.0 * h2 - 7.0 * r2); \
            float r = sqrt(r2); \
            if (r > 1e-6 * h) { \
                float w = h - r; \
                f_press -= vol * 0.5 * (p_i + rp.y) * kernel_grad(d, r2); \
                f_visc += vol * (vel[j].xyz - vi) * P.visc_lap * w; \
            } \
        } }
    FOR_NEIGHBORS(i, xi, VISIT)
#undef VISIT
    // The solid boundary mirrors the particle's pressure (p_b = p_i, rho_b = rho0; none
    // pulls the fluid onto a wall): -sum_b m / rho0 p_i grad W = -p_i g.
    vec3 gb;
    float rate;
    boundary(xi, vi, gb, rate);
    f_press -= max(p_i, 0.0) * gb;
    vec3 f = f_press + P.viscosity * f_visc + rho_i * P.gravity.xyz;
    float nl = length(n);
    if (nl >= P.tension_threshold) f -= P.tension * lap * n / nl;
    acc[i] = vec4(f / rho_i, 0.0);
}
