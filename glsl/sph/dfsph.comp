#version 450
// DFSPH (Bender & Koschier 2015, 2017), one pass per PASS, each solve a projected Jacobi
// on the signed residual. Densities relative to rho0, V = m / rho0. aux.x: the factor
// alpha = 1 / (|sum V grad W|^2 + sum |V grad W|^2); aux.y: this iteration's change of
// kappa; aux.z: the particle's fluid neighbours. rho_p.x counts the solid boundary
// (boundary.glsl), which also pushes with the particle's own kappa (as SPlisHSPlasH's DFSPH
// with boundary particles). aux2.x, aux2.y: the kappa the density and divergence solves
// have applied in this step, kept for the next step's warm start in vel.w (by euler.comp)
// and vhalf.w (by PREDICT): reordered with them. No collision response inside a solve:
// euler.comp's is the step's one.
//   FACTOR    density (as density.comp), alpha, neighbours, the step's neighbour lists;
//             and the divergence solve's WARM (its residual needs nothing FACTOR writes
//             for other particles)
//   WARM      kappa = 0; dk = last step's kappa rescaled to this dt where the particle
//             is compressing (r > 0, below), else 0
//   SOURCE    the signed residual r (density: rho*/rho0 - 1, rho* predicted from the
//             velocities; divergence: D(rho/rho0)/Dt, 0 with fewer than min_neighbors);
//             dk = max(kappa + r alpha / 2 / dt^2 (density) or / dt (divergence), 0) - kappa;
//             the iteration's error max(r, 0) (divergence: times dt)
//   VELOCITY  v -= dt sum V (dk_i + dk_j) grad W + dt dk_i sum_b V grad W; kappa += dk
// PREDICTED (the density solve's WARM and first VELOCITY): the predicted velocities
// v* = v + dt a_nonpressure are read as v + dt a (WARM) and stored by the first VELOCITY,
// which also keeps the divergence kappa: no predict pass of its own.
// The other passes, and DFSPH's forces (forces.comp), read the lists through
// FOR_NEIGHBORS (pressure.glsl).
// DIVERGENCE: 1 for the divergence-free solve, 0 for the constant-density solve.
#include "pressure.glsl"

// Jacobi's relaxation (SPlisHSPlasH's and IISPH's 0.5): alpha is the diagonal of a system
// that is not diagonally dominant, and a full step on the signed residual overshoots into
// oscillation that grows.
#define JACOBI_OMEGA 0.5
#if DIVERGENCE
#define KAPPA y
#else
#define KAPPA x
#endif

// Particle j's velocity as the solve sees it (PREDICTED: before the first VELOCITY has
// stored the prediction).
vec3 velocity(uint j, float dt) {
#if PREDICTED
    return vel[j].xyz + dt * acc[j].xyz;
#else
    return vel[j].xyz;
#endif
}

// The residual from the velocity divergence `rate` (see SOURCE).
float residual_of(uint i, float rate, float dt) {
#if DIVERGENCE
    // Too few neighbours for a meaningful divergence (the surface's spray): left out.
    return aux[i].z < float(P.min_neighbors) ? 0.0 : rate;
#else
    return rho_p[i].x / P.rest_density + dt * rate - 1.0;
#endif
}

// The signed residual of particle i (see SOURCE) with the velocities as they are.
float residual(uint i, float dt, float h2, float V) {
    vec3 xi = pos[i].xyz;
    vec3 vi = velocity(i, dt);
    vec3 gw;
    float rate;
    boundary(xi, vi, gw, rate);
#define VISIT(j) { vec3 d = xi - pos[j].xyz; float r2 = dot(d, d); \
        if (j != i && r2 < h2) rate += V * dot(vi - velocity(j, dt), grad_w(d, r2)); }
    FOR_NEIGHBORS(i, xi, VISIT)
#undef VISIT
    return residual_of(i, rate, dt);
}

// WARM's dk for a particle whose residual is r: the kept kappa (aux2 K's, in `kept`)
// rescaled to this dt where it compresses.
float warm_kappa(float r, float kept, float dt) {
    // The kept kappa moves a particle by dt^2 kappa grad W (density) or dt kappa grad W
    // (divergence): the same push at this step's dt takes it times (dt_prev / dt)^k.
    float ratio = P.dt_prev / dt;
#if DIVERGENCE
    kept *= ratio;
#else
    kept *= ratio * ratio;
#endif
    // All of it: with SPlisHSPlasH's half the 16K dam break's measured error at 1.33 ms
    // steps rose from 0.057% to 0.107% at a 0.1% target (a solve stops as soon as its
    // estimate is in; a better start leaves a better step).
    return r > 0.0 ? max(kept, 0.0) : 0.0;
}

void main() {
    SOLVE_START()
    uint i = global_id();
    float dt = P.gravity.w;
    float h2 = P.h * P.h;
    float V = vol0();
#if PASS == PASS_FACTOR
#if !DIVERGENCE
#error "FACTOR starts the divergence solve: build it with DIVERGENCE 1"
#endif
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
    vec3 vi = vel[i].xyz;
    vec3 sg = vec3(0.0);
    float s2 = 0.0, sum = 0.0;
    uint count = 0u;
    // The divergence solve's warm start: residual() in the same neighbour order.
    vec3 gv;
    float div_rate;
    boundary(xi, vi, gv, div_rate);
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        float r2 = dot(d, d);
        sum += kernel_w(r2);  // density, self included
        if (j != i && r2 < h2) {
            div_rate += V * dot(vi - vel[j].xyz, grad_w(d, r2));
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
    float rho = P.mass * sum + P.rest_density * boundary(xi, vec3(0.0), gw, rate);
    rho_p[i] = vec2(rho, 0.0);
    sg += gw;  // the boundary adds to the gradient sum (it does not move: no square)
    float denom = dot(sg, sg) + s2;
    aux[i] = vec4(denom > 1e-3 * P.proto_grad2 ? 1.0 / denom : 0.0, 0.0, float(count), 0.0);
    aux[i].y = warm_kappa(residual_of(i, div_rate, dt), vhalf[i].w, dt);
    aux2[i].y = 0.0;
#elif PASS == PASS_WARM
#if DIVERGENCE || !PREDICTED
#error "WARM is the density solve's (PREDICTED 1): FACTOR warms the divergence solve"
#endif
    if (!sph_alive(i)) return;
    aux[i].y = warm_kappa(residual(i, dt, h2, V), vel[i].w, dt);
    aux2[i].KAPPA = 0.0;
#elif PASS == PASS_SOURCE
    bool live = sph_alive(i);
    float e = 0.0;
    if (live) {
        float r = residual(i, dt, h2, V);
        float kappa = aux2[i].KAPPA;
#if DIVERGENCE
        float next = max(kappa + JACOBI_OMEGA * r * aux[i].x / dt, 0.0);
        e = max(r, 0.0) * dt;
#else
        float next = max(kappa + JACOBI_OMEGA * r * aux[i].x / (dt * dt), 0.0);
        e = max(r, 0.0);
#endif
        aux[i].y = next - kappa;
    }
    reduce_error(e, live);
#elif PASS == PASS_VELOCITY
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
    float ki = aux[i].y;
    // The boundary answers with the particle's own stiffness.
    vec3 gw;
    float rate;
    boundary(xi, vec3(0.0), gw, rate);
    vec3 dv = -dt * ki * gw;
#define VISIT(j) { vec3 d = xi - pos[j].xyz; float r2 = dot(d, d); \
        if (j != i && r2 < h2) dv -= dt * V * (ki + aux[j].y) * grad_w(d, r2); }
    FOR_NEIGHBORS(i, xi, VISIT)
#undef VISIT
    // Neighbours read aux.y here, never vel.xyz or aux2.
    vel[i].xyz = velocity(i, dt) + dv;
    aux2[i].KAPPA += ki;
#if PREDICTED
    vhalf[i].w = aux2[i].y;  // the divergence kappa, for the next step's warm start
#endif
#else
#error "PASS names no DFSPH pass"
#endif
}
