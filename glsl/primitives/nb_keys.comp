#version 450
// Neighbour search, step 1 for grid and hash: each particle's cell key; value = index.
// A dead slot (pos.w < 0, e.g. an emitter's unborn particle) gets the key one past the
// last cell, so every sort puts it after the live particles and no query visits it.
#include "common/index.glsl"
#include "nb_common.glsl"
#define NB_CELL_ONLY
#include "neighbors.glsl"
layout(std430, binding = NBK_B_POS) readonly buffer Pos { vec4 pos[]; };  // positions
layout(std430, binding = NBK_B_KEYS) writeonly buffer Keys { uint keys[]; };  // cell keys
layout(std430, binding = NBK_B_VALS) writeonly buffer Vals { uint vals[]; };  // indices
// The counting sort's first pass, done here (NB_CELL_COUNTS; count.comp's, which it
// replaces): per-bin counts (cells + 1 bins, the dead slots' last; counts[bins] counts keys
// past them) and each particle's in-bin rank.
layout(std430, binding = NBK_B_COUNTS) buffer Counts { uint counts[]; };
layout(std430, binding = NBK_B_RANK) writeonly buffer Rank { uint rank[]; };
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    vec4 p = pos[i];
#if NB_STRATEGY == NB_GRID
    uint dead = NB_DIMS.x * NB_DIMS.y * NB_DIMS.z;
    uint k = p.w < 0.0 ? dead : nb_grid_id(nb_grid_cell(p.xyz));
#elif NB_STRATEGY == NB_HASH
    uint dead = NB_TABLE;
    uint k = p.w < 0.0 ? dead : nb_hash(nb_cell_of(p.xyz));
#else
#error "nb_keys.comp serves the grid and hash searches only"
#endif
    keys[i] = k;
    vals[i] = i;
#if NB_CELL_COUNTS
    uint bins = dead + 1u;
    if (k >= bins) { atomicAdd(counts[bins], 1u); k = bins - 1u; }
    rank[i] = atomicAdd(counts[k], 1u);
#endif
}
