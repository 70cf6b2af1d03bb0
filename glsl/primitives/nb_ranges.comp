#version 450
// Cell start/end from keys sorted by a network sort (the cell arrays were zeroed first).
#include "common/index.glsl"
layout(std430, binding = NBR_B_KEYS) readonly buffer Keys { uint keys[]; };  // sorted keys
layout(std430, binding = NBR_B_START) buffer Start { uint start[]; };  // cell starts
layout(std430, binding = NBR_B_END) buffer End { uint end_[]; };  // cell ends
layout(push_constant) uniform Push { uint n; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    uint k = keys[i];
    if (i == 0u || keys[i - 1u] != k) start[k] = i;
    if (i + 1u == pc.n || keys[i + 1u] != k) end_[k] = i + 1u;
}
