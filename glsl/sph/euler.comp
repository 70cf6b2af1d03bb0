#version 450
// Symplectic Euler for PCISPH and DFSPH: v += dt (a_nonpressure + a_pressure) (PCISPH's
// pressure acceleration in aux2; DFSPH has corrected vel itself and zeroes both), then
// x += dt v and the collision response. vel.w: DFSPH's density kappa, kept for the next
// step's warm start. rho_p.y: the step's pressure in Pa (PCISPH's p / rho0 and DFSPH's
// density kappa, times rho0: both solve a = -V sum (k_i + k_j) grad W, k = p / rho0).
// With fluid.cfl set it also takes the next step's dt from the velocities it leaves
// (cfl.glsl), so a step that follows in the same recording needs no cfl.comp.
#define CFL_REDUCE
#include "pressure.glsl"
void main() {
    uint i = global_id();
    vec4 p = i < pc.n ? pos[i] : vec4(0.0, 0.0, 0.0, -1.0);
    vec3 v = i < pc.n ? vel[i].xyz : vec3(0.0);
    if (sph_alive(i)) {
        float dt = P.gravity.w;
        if (P.solver == SOLVER_PCISPH) v += dt * (acc[i].xyz + aux2[i].xyz);
        vec3 x = p.xyz + dt * v;
        vec3 v2 = v;
        collide(x, v, v2);
        pos[i].xyz = x;
        vel[i] = vec4(v, P.solver == SOLVER_DFSPH ? aux2[i].x : vel[i].w);
        float k = P.solver == SOLVER_DFSPH ? aux2[i].x : rho_p[i].y;
        rho_p[i].y = P.rest_density * k;
    }
    if (P.cfl <= 0.0) return;  // uniform
    // cfl.comp's particles: the first n with pos.w >= 0
    float m = p.w >= 0.0 ? dot(v, v) : 0.0;
    uint parts = (pc.n + PARTICLE_WG - 1u) / PARTICLE_WG;
    float dt, prev;
    if (cfl_reduce(m, parts, vec4(P.cfl, P.h, P.dt_max, P.cfl_speed), true, dt, prev)) {
        PO.gravity.w = dt;
        PO.dt_prev = prev;
    }
}
