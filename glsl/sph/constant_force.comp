#version 450
// A uniform extra acceleration added after the forces pass (src/sim/sph/hooks.rs).
#include "common/index.glsl"
layout(std430, binding = CF_B_ACC) buffer Acc { vec4 acc[]; };
layout(push_constant) uniform Push { vec4 accel; uint n; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    acc[i].xyz += pc.accel.xyz;
}
