#version 450
#extension GL_EXT_control_flow_attributes : require
// The device's FMA rate, for bench render's floor column (src/bench/floor.rs): every
// invocation runs `iters` iterations of 8 independent vec4 FMA chains (64 FLOPs each) and
// stores their sum, so nothing is optimised away.
#include "common/index.glsl"
layout(std430, binding = FMA_B_OUT) writeonly buffer Out { vec4 out_values[]; };
layout(push_constant) uniform Push { uint iters; } pc;
void main() {
    vec4 x[8];
    [[unroll]] for (int j = 0; j < 8; ++j) x[j] = vec4(float(global_id() + uint(j)));
    vec4 m = vec4(0.999), c = vec4(0.5);  // x -> 500 + (x - 500) 0.999^k: finite
    uint k = 0u;
    for (; k < pc.iters; ++k) {
        [[unroll]] for (int j = 0; j < 8; ++j) x[j] = fma(x[j], m, c);
    }
    vec4 s = vec4(0.0);
    [[unroll]] for (int j = 0; j < 8; ++j) s += x[j];
    out_values[global_id()] = s;
}
