#version 450
// PCISPH (Solenthaler & Pajarola 2009), one pass per PASS, neighbours from the step's start
// positions. aux.xyz: predicted position x*, aux.w: delta; aux2.xyz: pressure acceleration
// (zeroed by FACTOR, which starts the solve); rho_p.y: pressure (0 from the density pass), in units of
// rho0 (p / rho0; euler.comp leaves Pa). The solid boundary (boundary.glsl) counts in the
// densities and pushes with the particle's own pressure; delta is the fluid's alone (with
// the boundary's gradient in it, the solve at 0.1% diverged in a resting pool: near a
// wall the fluid's one-sided sum and the boundary's cancel, so delta takes a full
// neighbourhood's value while the wall answers with p_i alone).
//   FACTOR    delta_i = 1/2 / (2 dt^2 (|sum V grad W|^2 + sum |V grad W|^2)) at x
//   PREDICT   x* = x + dt (v + dt (a_np + a_p)), collided
//   PRESSURE  rho* at x*; p += delta_i (rho*/rho0 - 1), 0 <= p <= cap;
//             error max(rho*/rho0 - 1, 0)
//   ACCEL     a_p = -V sum (p_i + p_j) grad W(x*_ij)
// The paper's delta is one prototype's (a full neighbourhood); each particle's own, as
// here, does not overshoot where the neighbourhood is one-sided (walls, the surface), where
// the prototype's diverged in our dam break. Relaxed by 1/2 as IISPH's Jacobi update.
#include "pressure.glsl"
void main() {
    SOLVE_START()
    uint i = global_id();
    float dt = P.gravity.w;
    float h2 = P.h * P.h;
#if PASS == PASS_FACTOR
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
    vec3 sg = vec3(0.0);
    float s2 = 0.0;
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        float r2 = dot(d, d);
        if (j != i && r2 < h2) {
            vec3 g = vol0() * grad_w(d, r2);
            sg += g;
            s2 += dot(g, g);
        }
    NB_END
    float k = max(dot(sg, sg) + s2, 1e-3 * P.proto_grad2);
    aux[i] = vec4(pos[i].xyz, 0.5 / (2.0 * dt * dt * k));
    aux2[i] = vec4(0.0);  // the pressure acceleration starts at zero
#elif PASS == PASS_PREDICT
    if (!sph_alive(i)) return;
    vec3 v = vel[i].xyz + dt * (acc[i].xyz + aux2[i].xyz);
    vec3 x = pos[i].xyz + dt * v;
    vec3 v2 = v;
    collide(x, v, v2);
    aux[i].xyz = x;
#elif PASS == PASS_PRESSURE
    bool live = sph_alive(i);
    float e = 0.0;
    if (live) {
        vec3 xi = aux[i].xyz;
        float sum = 0.0;
        NB_BEGIN(xi, P.h, j)
            vec3 d = xi - aux[j].xyz;
            float r2 = dot(d, d);
            sum += kernel_w(r2);
        NB_END
        vec3 gw;
        float rate;
        float rho = P.mass * sum + P.rest_density * boundary(xi, vec3(0.0), gw, rate);
        float err = rho / P.rest_density - 1.0;
        // At most the pressure that resolves a 20% compression of a full neighbourhood in
        // one step: a clump the walls pin (whose density no pressure lowers) would
        // otherwise raise its pressure every iteration and fling its neighbours.
        float cap = 0.2 / (2.0 * dt * dt * P.proto_grad2);
        rho_p[i].y = clamp(rho_p[i].y + aux[i].w * err, 0.0, cap);
        e = max(err, 0.0);
    }
    reduce_error(e, live);
#elif PASS == PASS_ACCEL
    if (!sph_alive(i)) return;
    vec3 xi = aux[i].xyz;
    float pi = rho_p[i].y;
    vec3 a = vec3(0.0);
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - aux[j].xyz;
        float r2 = dot(d, d);
        if (j != i && r2 < h2) a -= (pi + rho_p[j].y) * grad_w(d, r2);
    NB_END
    // p is in units of rho0 (see delta): a = -V sum (p_i + p_j) grad W - p_i sum_b V grad W.
    vec3 gw;
    float rate;
    boundary(xi, vec3(0.0), gw, rate);
    aux2[i] = vec4(vol0() * a - pi * gw, 0.0);
#else
#error "PASS names no PCISPH pass"
#endif
}
