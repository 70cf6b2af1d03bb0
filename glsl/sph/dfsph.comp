#version 450
// DFSPH (Bender & Koschier 2015, 2017), one pass per PASS. Densities relative to rho0,
// V = m / rho0. aux.x: factor alpha = 1 / (|sum V grad W|^2 + sum |V grad W|^2);
// aux.y: the solve's source s (density: max(rho_adv / rho0 - 1, 0), rho_adv predicted
// from the velocities; divergence: max(D(rho/rho0)/Dt, 0)). rho_p.x counts the solid
// boundary (boundary.glsl), which also pushes with the particle's own stiffness (as
// SPlisHSPlasH's DFSPH with boundary particles). aux2.x, aux2.y: the
// stiffness kappa the density and divergence solves apply in this step, kept for the next
// step's warm start in vel.w (by euler.comp) and vhalf.w (by PREDICT): reordered with them.
//   FACTOR    density (as density.comp), alpha, the step's neighbour lists
//   WARM      kappa = last step's / 2 (halved, so a stale kappa fades);
//             v -= dt sum V (kappa_i + kappa_j) grad W
//   SOURCE    s, and the iteration's error: s (density), s dt (divergence)
//   VELOCITY  k = s alpha / dt^2 (density) or / dt (divergence); v -= dt sum V (k_i + k_j)
//             grad W; kappa += k
//   PREDICT   v* = v + dt a_nonpressure; the divergence kappa kept
// The other passes, and DFSPH's forces (forces.comp), read the lists through
// FOR_NEIGHBORS (pressure.glsl).
// DIVERGENCE: 1 for the divergence-free solve, 0 for the constant-density solve.
#include "pressure.glsl"

#if DIVERGENCE
float kappa_of(uint i) { return 0.5 * vhalf[i].w; }
float k_of(uint i, float dt) { return aux[i].y * aux[i].x / dt; }
#define KAPPA y
#else
float kappa_of(uint i) { return 0.5 * vel[i].w; }
float k_of(uint i, float dt) { return aux[i].y * aux[i].x / (dt * dt); }
#define KAPPA x
#endif

void main() {
    uint i = global_id();
    float dt = P.gravity.w;
    float h2 = P.h * P.h;
    float V = vol0();
#if PASS == PASS_FACTOR
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
    vec3 sg = vec3(0.0);
    float s2 = 0.0, sum = 0.0;
    uint count = 0u;
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        float r2 = dot(d, d);
        if (r2 < h2) { float q = h2 - r2; sum += q * q * q; }  // density, self included
        if (j != i && r2 < h2) {
            vec3 g = V * grad_w(d, r2);
            sg += g;
            s2 += dot(g, g);
            if (count < P.list_max) nb_list[(count + 1u) * pc.n + i] = j;
            ++count;
        }
    NB_END
    if (P.list_max != 0u) {
        nb_list[i] = count;
        if (count > P.list_max) atomicAdd(list_overflows, 1u);
    }
    // As density.comp, which DFSPH skips (the same sum in the same order).
    vec3 gw;
    float rate;
    float rho = P.mass * P.poly6 * sum + P.rest_density * boundary(xi, vec3(0.0), gw, rate);
    rho_p[i] = vec2(rho, 0.0);
    sg += gw;  // the boundary adds to the gradient sum (it does not move: no square)
    float denom = dot(sg, sg) + s2;
    aux[i] = vec4(denom > 1e-3 * P.proto_grad2 ? 1.0 / denom : 0.0, 0.0, 0.0, 0.0);
#elif PASS == PASS_SOURCE
    bool live = sph_alive(i);
    float e = 0.0;
    if (live) {
        vec3 xi = pos[i].xyz;
        vec3 vi = vel[i].xyz;
        vec3 gw;
        float rate;
        boundary(xi, vi, gw, rate);
#define VISIT(j) { vec3 d = xi - pos[j].xyz; float r2 = dot(d, d); \
            if (j != i && r2 < h2) rate += V * dot(vi - vel[j].xyz, grad_w(d, r2)); }
        FOR_NEIGHBORS(i, xi, VISIT)
#undef VISIT
#if DIVERGENCE
        float s = max(rate, 0.0);
        e = s * dt;
#else
        float s = max(rho_p[i].x / P.rest_density + dt * rate - 1.0, 0.0);
        e = s;
#endif
        aux[i].y = s;
    }
    reduce_error(e, live);
#elif PASS == PASS_VELOCITY || PASS == PASS_WARM
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
#if PASS == PASS_WARM
    float ki = kappa_of(i);
#else
    float ki = k_of(i, dt);
#endif
    // The boundary answers with the particle's own stiffness.
    vec3 gw;
    float rate;
    boundary(xi, vec3(0.0), gw, rate);
    vec3 dv = -dt * ki * gw;
#if PASS == PASS_WARM
#define KAPPA_J(j) kappa_of(j)
#else
#define KAPPA_J(j) k_of(j, dt)
#endif
#define VISIT(j) { vec3 d = xi - pos[j].xyz; float r2 = dot(d, d); \
        if (j != i && r2 < h2) dv -= dt * V * (ki + KAPPA_J(j)) * grad_w(d, r2); }
    FOR_NEIGHBORS(i, xi, VISIT)
#undef VISIT
    // A velocity into a wall is still answered as the step will.
    vec3 v = vel[i].xyz + dv;
    wall_response(pos[i].xyz, dt, v);
    // Neighbours read vel.w, vhalf.w or aux here, never vel.xyz or aux2.
    vel[i].xyz = v;
#if PASS == PASS_WARM
    aux2[i].KAPPA = ki;
#else
    aux2[i].KAPPA += ki;
#endif
#elif PASS == PASS_PREDICT
    if (!sph_alive(i)) return;
    vec3 v = vel[i].xyz + dt * acc[i].xyz;
    wall_response(pos[i].xyz, dt, v);
    vel[i].xyz = v;
    vhalf[i].w = aux2[i].y;
#else
#error "PASS names no DFSPH pass"
#endif
}
