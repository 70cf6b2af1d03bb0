#version 450
#extension GL_EXT_control_flow_attributes : require
// The S-buffer built in compute (--build compute) from the per-tile lists: one workgroup
// per 8 x 8 pixel block walks its tile's pairs in batches of 64 staged in shared memory;
// each pixel takes the metaballs whose rectangle (the billboard's) holds it. PASS 0: the
// count into offsets[p] (then scanned, as the raster count). PASS 1: the fill, in the
// tile's depth order, so each range is already sorted, and offsets[p] advanced to its
// range's end as the raster fill leaves it. Entries past the capacity count as overflow.
#include "common/index.glsl"
#include "common.glsl"
#include "blocks.glsl"

void main() {
    uvec2 pix = block_pixel();
    bool valid = pix.x < P.width && pix.y < P.height;
    uint p = valid ? pixel_index(pix) : 0u;
    uvec2 range = tile_ranges[tile_of(block_origin())];
    uint count = 0u;
#if PASS == 1
    uint start = valid ? offsets[p] : 0u;
#elif PASS != 0
#error "PASS is 0 (count) or 1 (fill)"
#endif
    // Every invocation of the block reads the same pair at once (one broadcast load).
    uint k = range.x;
    for (; k < range.y; k += 8u) {
        [[unroll]] for (uint u = 0u; u < 8u; ++u) {
            uint i = k + u;
            if (i < range.y) {
                uint id = pair_ids[i];
                if (rect_holds(rects[id], pix)) {
#if PASS == 1
                    uint slot = start + count;
                    if (slot < P.list_capacity) list[slot] = id;
#endif
                    count++;
                }
            }
        }
    }
    // llvmpipe's loop budget (march.comp): a cut loop makes the frame wrong; reported.
    if (k < range.y && valid) atomicAdd(stats.budget_pixels, 1u);
    if (!valid) return;
#if PASS == 0
    offsets[p] = count;
#else
    offsets[p] = start + count;
    uint end = start + count;
    if (end > P.list_capacity) atomicAdd(stats.overflow, end - max(start, P.list_capacity));
#endif
}
