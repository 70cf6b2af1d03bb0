#version 450
// Morton code of each position relative to the box from the bounds pass; value = index.
// A dead slot (pos.w < 0) gets the largest key, past every code: it sorts last and no
// query range reaches it.
#include "common/index.glsl"
#include "morton.glsl"
layout(std430, binding = MORTON_B_POS) readonly buffer Pos { vec4 pos[]; };  // positions
layout(std430, binding = MORTON_B_BOUNDS) readonly buffer Bounds { vec4 box[]; };  // min, max
layout(std430, binding = MORTON_B_KEYS) writeonly buffer Keys { uint keys[]; };  // codes
layout(std430, binding = MORTON_B_VALS) writeonly buffer Vals { uint vals[]; };  // indices
layout(push_constant) uniform Push { uint n; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    vec4 p = pos[i];
    keys[i] = p.w < 0.0 ? 0xFFFFFFFFu : morton_code(morton_cell(p.xyz, box[0].xyz, box[1].xyz));
    vals[i] = i;
}
