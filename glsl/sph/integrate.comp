#version 450
// Leapfrog (Kelager 2006): v(t+dt/2) = v(t-dt/2) + a dt, x += v(t+dt/2) dt,
// v(t) = average of the half steps; then collision response against colliders and the
// domain box (common.glsl's collide). WCSPH's integrator; the pressure solvers use
// symplectic Euler (euler.comp, pbf.comp).
#include "common.glsl"

void main() {
    uint i = global_id();
    if (i >= sph_live() || pos[i].w < 0.0) return;  // past the live, or dead
    float dt = P.gravity.w;
    vec3 a = acc[i].xyz;
    vec3 vh_old = vhalf[i].xyz;
    vec3 vh = vh_old + a * dt;
    vec3 x = pos[i].xyz + vh * dt;
    vec3 v = 0.5 * (vh_old + vh);
    collide(x, vh, v);
    pos[i].xyz = x;
    vhalf[i].xyz = vh;
    vel[i].xyz = v;
}
