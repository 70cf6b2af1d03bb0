#version 450
// Symplectic Euler for PCISPH and DFSPH: v += dt (a_nonpressure + a_pressure) (PCISPH's
// pressure acceleration in aux2; DFSPH has corrected vel itself and zeroes both), then
// x += dt v and the collision response. vel.w: DFSPH's density kappa, kept for the next
// step's warm start. rho_p.y: the step's pressure in Pa (PCISPH's p / rho0 and DFSPH's
// density kappa, times rho0: both solve a = -V sum (k_i + k_j) grad W, k = p / rho0).
#include "pressure.glsl"
void main() {
    uint i = global_id();
    if (!sph_alive(i)) return;
    float dt = P.gravity.w;
    vec3 v = vel[i].xyz;
    if (P.solver == SOLVER_PCISPH) v += dt * (acc[i].xyz + aux2[i].xyz);
    vec3 x = pos[i].xyz + dt * v;
    vec3 v2 = v;
    collide(x, v, v2);
    pos[i].xyz = x;
    vel[i] = vec4(v, P.solver == SOLVER_DFSPH ? aux2[i].x : vel[i].w);
    float k = P.solver == SOLVER_DFSPH ? aux2[i].x : rho_p[i].y;
    rho_p[i].y = P.rest_density * k;
}
