#version 450
// Per-tile lists, steps 2 and 3, one invocation per depth rank r (front to back). PASS 0:
// how many tiles its metaball's rectangle overlaps (scanned into each rank's first pair;
// the extra slot P.n becomes the total). PASS 1: its pairs, key tile << rank_bits | r, so
// sorting the keys orders them by tile, then by depth. Pairs past the capacity are not
// written (tile_ranges.comp counts them as overflow).
#include "common/index.glsl"
#include "common.glsl"

// The tiles [x0, x1) x [y0, y1) a packed pixel rectangle overlaps.
uvec4 rect_tiles(uvec2 r) {
    uvec4 px = uvec4(r.x & 0xFFFFu, r.x >> 16, r.y & 0xFFFFu, r.y >> 16);
    if (px.x >= px.z || px.y >= px.w) return uvec4(0u);
    return uvec4(px.xy / P.tile, (px.zw + P.tile - 1u) / P.tile);
}

void main() {
    uint r = global_id();
#if PASS == 0
    if (r == P.n) pair_counts[r] = 0u;
#endif
    if (r >= P.n) return;
    uint id = ball_ids[r];
    uvec4 t = rect_tiles(rects[id]);
#if PASS == 0
    pair_counts[r] = (t.z - t.x) * (t.w - t.y);
#elif PASS == 1
    uint dst = pair_counts[r];
    uint ty = t.y, tx = t.x;
    // One loop over the rectangle's tiles (a near sphere covers them all).
    uint cols = t.z - t.x, count = cols * (t.w - t.y), k = 0u;
    for (; k < count; ++k) {
        uint tile = (t.y + k / cols) * P.tiles_x + t.x + k % cols;
        if (dst + k < P.pair_capacity) {
            pair_keys[dst + k] = tile << P.rank_bits | r;
            pair_ids[dst + k] = id;
        }
    }
    // llvmpipe's loop budget (march.comp): a cut loop makes the frame wrong; reported.
    if (k < count) atomicAdd(stats.budget_pixels, 1u);
#else
#error "PASS is 0 (count) or 1 (emit)"
#endif
}
