#version 450
// Per-tile lists, step 5, one invocation per sorted pair: each tile's range [x, y) of the
// pairs (sorted by tile, then depth), and each pair's metaball (xyz, view depth) gathered
// in that order, so a tile's candidates are read contiguously. Invocation 0 records the
// frame's pairs and counts those past the capacity as overflow (the frame is redone).
#include "common/index.glsl"
#include "common.glsl"
void main() {
    uint i = global_id();
    uint total = pair_counts[P.n];
    if (i == 0u) {
        stats.pairs = total;
        if (total > P.pair_capacity) atomicAdd(stats.overflow, total - P.pair_capacity);
    }
    uint m = min(total, P.pair_capacity);
    if (i >= m) return;
    uint tile = pair_keys[i] >> P.rank_bits;
    if (i == 0u || (pair_keys[i - 1u] >> P.rank_bits) != tile) tile_ranges[tile].x = i;
    if (i + 1u == m || (pair_keys[i + 1u] >> P.rank_bits) != tile) tile_ranges[tile].y = i + 1u;
    uint id = pair_ids[i];
    tile_balls[i] = vec4(centers[id].xyz, depths[id]);
}
