#version 450
// Self-test of the compute path: y[i] = a * x[i] + y[i], plus an integer mix.
#include "common/index.glsl"
layout(std430, binding = 0) readonly buffer X { float x[]; };  // x
layout(std430, binding = 1) buffer Y { float y[]; };  // y (in/out)
layout(std430, binding = 2) buffer U { uint u[]; };  // u (in/out)
layout(push_constant) uniform Push { float a; uint n; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    y[i] = pc.a * x[i] + y[i];
    u[i] = u[i] * 2654435761u + i;
}
