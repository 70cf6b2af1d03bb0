#version 450
// Position based fluids (Macklin & Mueller 2013), one pass per PASS, neighbours from the
// step's start positions. aux.xyz: predicted position x* (after the solve: vorticity
// omega); aux2.xyz: the position correction (after the solve: the XSPH velocity change);
// rho_p.y: lambda (after the solve: the pressure in Pa, -rho0 sum lambda / dt^2, the sum
// over the iterations kept in aux.w). V = m / rho0. The solid boundary (boundary.glsl)
// counts in the constraint and moves the particle alone (lambda_b = 0).
//   PREDICT    x* = x + dt (v + dt a_nonpressure), collided
//   LAMBDA     C = max(rho*/rho0 - 1, 0); lambda = -C / (sum_k |grad_k C|^2 + eps);
//              the iteration's error C
//   DELTA      dx = sum V (lambda_i + lambda_j + s_corr) grad W(x*_ij),
//              s_corr = -k (W(r) / W(dq h))^n / sum |V grad W|^2 (full neighbourhood)
//   APPLY      x* += dx, collided
//   VELOCITY   v = (x* - x) / dt, x = x*
//   VORTICITY  omega = sum V grad W x (v_j - v_i); XSPH dv = c sum V (v_j - v_i) W
//   CONFINE    eta = sum V (|omega_j| - |omega_i|) grad W, N = eta / |eta|;
//              v += dt epsilon (N x omega) + dv
#include "pressure.glsl"
void main() {
    SOLVE_START()
    uint i = global_id();
    float dt = P.gravity.w;
    float h2 = P.h * P.h;
    float V = vol0();
#if PASS == PASS_PREDICT
    if (!sph_alive(i)) return;
    vec3 v = vel[i].xyz + dt * acc[i].xyz;
    vec3 x = pos[i].xyz + dt * v;
    vec3 v2 = v;
    collide(x, v, v2);
    aux[i] = vec4(x, 0.0);
#elif PASS == PASS_LAMBDA
    bool live = sph_alive(i);
    float e = 0.0;
    if (live) {
        vec3 xi = aux[i].xyz;
        float sum = 0.0;
        vec3 sg = vec3(0.0);
        float s2 = 0.0;
        NB_BEGIN(xi, P.h, j)
            vec3 d = xi - aux[j].xyz;
            float r2 = dot(d, d);
            if (r2 < h2) {
                sum += kernel_w(r2);
                if (j != i) {
                    vec3 g = V * grad_w(d, r2);
                    sg += g;
                    s2 += dot(g, g);
                }
            }
        NB_END
        vec3 gw;
        float rate;
        float rho_b = boundary(xi, vec3(0.0), gw, rate);
        sg += gw;
        float c = max(P.mass * sum / P.rest_density + rho_b - 1.0, 0.0);
        float lambda = -c / (dot(sg, sg) + s2 + P.pbf_relaxation * P.proto_grad2);
        rho_p[i].y = lambda;
        aux[i].w += lambda;  // neighbours read aux.xyz only
        e = c;
    }
    reduce_error(e, live);
#elif PASS == PASS_DELTA
    if (!sph_alive(i)) return;
    vec3 xi = aux[i].xyz;
    float li = rho_p[i].y;
    vec3 dx = vec3(0.0);
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - aux[j].xyz;
        float r2 = dot(d, d);
        if (j != i && r2 < h2) {
            // k relative to a full neighbourhood's constraint stiffness (lambda's units).
            float scorr = -P.scorr_k * pow(kernel_w(r2) * P.scorr_inv_w, P.scorr_n) / P.proto_grad2;
            dx += V * (li + rho_p[j].y + scorr) * grad_w(d, r2);
        }
    NB_END
    vec3 gw;
    float rate;
    boundary(xi, vec3(0.0), gw, rate);
    aux2[i] = vec4(dx + li * gw, 0.0);
#elif PASS == PASS_APPLY
    if (!sph_alive(i)) return;
    vec3 x = aux[i].xyz + aux2[i].xyz;
    vec3 v = vec3(0.0), v2 = vec3(0.0);
    collide(x, v, v2);
    aux[i].xyz = x;
#elif PASS == PASS_VELOCITY
    if (!sph_alive(i)) return;
    vec3 x = aux[i].xyz;
    vel[i].xyz = (x - pos[i].xyz) / dt;
    pos[i].xyz = x;
    rho_p[i].y = -P.rest_density * aux[i].w / (dt * dt);
#elif PASS == PASS_VORTICITY
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
    vec3 vi = vel[i].xyz;
    vec3 w = vec3(0.0), dv = vec3(0.0);
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        float r2 = dot(d, d);
        if (j != i && r2 < h2) {
            vec3 vji = vel[j].xyz - vi;
            w += V * cross(grad_w(d, r2), vji);
            dv += V * vji * kernel_w(r2);
        }
    NB_END
    aux[i] = vec4(w, 0.0);
    aux2[i] = vec4(P.xsph * dv, 0.0);
#elif PASS == PASS_CONFINE
    if (!sph_alive(i)) return;
    vec3 xi = pos[i].xyz;
    vec3 wi = aux[i].xyz;
    float wl = length(wi);
    vec3 eta = vec3(0.0);
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        float r2 = dot(d, d);
        if (j != i && r2 < h2) eta += V * (length(aux[j].xyz) - wl) * grad_w(d, r2);
    NB_END
    float el = length(eta);
    vec3 f = el > 1e-6 / P.h ? P.vorticity * cross(eta / el, wi) : vec3(0.0);
    vel[i].xyz += dt * f + aux2[i].xyz;
#else
#error "PASS names no PBF pass"
#endif
}
