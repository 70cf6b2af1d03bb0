#version 450
// Test scene: particles fall towards an attractor at the origin (force ~ 1/(r^2 + eps),
// the "local attractor" of seed 003), explicit Euler, reflected by the box [-1, 1]^3.
#include "common/index.glsl"
layout(std430, binding = ORB_B_POS) buffer Pos { vec4 pos[]; };  // xyz, w = radius
layout(std430, binding = ORB_B_VEL) buffer Vel { vec4 vel[]; };  // xyz, w unused
layout(push_constant) uniform Push { float dt; float strength; float eps; uint n; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    vec3 p = pos[i].xyz;
    vec3 v = vel[i].xyz;
    float r2 = dot(p, p);
    v += -p * inversesqrt(r2 + pc.eps) * (pc.strength / (r2 + pc.eps)) * pc.dt;
    p += v * pc.dt;
    // Reflect at the walls; the position is mirrored so it stays inside.
    for (int k = 0; k < 3; ++k) {
        if (p[k] > 1.0) { p[k] = 2.0 - p[k]; v[k] = -v[k]; }
        if (p[k] < -1.0) { p[k] = -2.0 - p[k]; v[k] = -v[k]; }
    }
    pos[i].xyz = p;
    vel[i].xyz = v;
}
