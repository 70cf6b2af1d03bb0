// Particle-system drawing: what the vertex and fragment stages share.
#include "common.glsl"
layout(std430, binding = PDRAW_B_PARAMS) readonly buffer Params { SystemParams sp; };
layout(std430, binding = PDRAW_B_POS) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = PDRAW_B_VEL) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = PDRAW_B_PREV) readonly buffer Prev { vec4 prev[]; };
layout(std430, binding = PDRAW_B_COLOR) readonly buffer Color { vec4 color[]; };
// Instance -> slot: an alive list, or sorted values (NO_SLOT: skip).
layout(std430, binding = PDRAW_B_ORDER) readonly buffer Order { uint order[]; };
// The sprite texture: SPRITE_SIZE^2 coverage values, sampled bilinearly.
layout(std430, binding = PDRAW_B_SPRITE) readonly buffer Sprite { float sprite[]; };
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 right;   // camera right, w = point size (pixels)
    vec4 up;      // camera up, w = time after this frame's step (s)
    vec4 screen;  // x 2 / width, y 2 / height, z frame dt (s), w sprite texture side
    uint offset;  // first entry of `order`
    uint identity;  // 1: instance = slot (closed form, unsorted)
    uint pad[2];
} pc;
