#version 450
// Neighbour search, step 1 for grid and hash: each particle's cell key; value = index.
#include "common/index.glsl"
#include "nb_common.glsl"
#define NB_CELL_ONLY
#include "neighbors.glsl"
layout(std430, binding = NBK_B_POS) readonly buffer Pos { vec4 pos[]; };  // positions
layout(std430, binding = NBK_B_KEYS) writeonly buffer Keys { uint keys[]; };  // cell keys
layout(std430, binding = NBK_B_VALS) writeonly buffer Vals { uint vals[]; };  // indices
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    vec3 p = pos[i].xyz;
#if NB_STRATEGY == NB_GRID
    keys[i] = nb_grid_id(nb_grid_cell(p));
#else
    keys[i] = nb_hash(nb_cell_of(p));
#endif
    vals[i] = i;
}
