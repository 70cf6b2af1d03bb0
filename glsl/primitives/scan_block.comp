#version 450
// Scan pass 3: scan each block of WG * ITEMS elements in shared memory and add the block's
// offset (the exclusive scan of the block sums). Input and output may be the same buffer.
#include "common/index.glsl"
#include "workgroup.glsl"
layout(constant_id = 1) const uint ITEMS = 8;
layout(std430, binding = 0) readonly buffer In { uint data[]; };      // binding 0: this segment
layout(std430, binding = 1) writeonly buffer Out { uint result[]; };  // binding 1: this segment
layout(std430, binding = 2) readonly buffer Offs { uint offsets[]; }; // binding 2: block offsets
layout(push_constant) uniform Push { uint n; uint block_base; uint flags; } pc;
const uint INCLUSIVE = 1u, HAS_OFFSETS = 2u;
// One padding word per 32 avoids bank conflicts on the per-thread contiguous reads.
#define PAD(i) ((i) + ((i) >> 5))
shared uint tile[PAD(gl_WorkGroupSize.x * ITEMS)];
void main() {
    uint wg = gl_WorkGroupSize.x;
    uint lid = gl_LocalInvocationIndex;
    uint base = group_id() * wg * ITEMS;
    for (uint k = 0; k < ITEMS; ++k) {
        uint j = k * wg + lid;
        tile[PAD(j)] = base + j < pc.n ? data[base + j] : 0u;
    }
    barrier();
    uint s = 0;
    for (uint k = 0; k < ITEMS; ++k) s += tile[PAD(lid * ITEMS + k)];
    uint total;
    uint pre = wg_exclusive_scan(s, total);
    if ((pc.flags & HAS_OFFSETS) != 0u) pre += offsets[pc.block_base + group_id()];
    bool inclusive = (pc.flags & INCLUSIVE) != 0u;
    for (uint k = 0; k < ITEMS; ++k) {
        uint j = PAD(lid * ITEMS + k);
        uint v = tile[j];
        tile[j] = inclusive ? pre + v : pre;
        pre += v;
    }
    barrier();
    for (uint k = 0; k < ITEMS; ++k) {
        uint j = k * wg + lid;
        if (base + j < pc.n) result[base + j] = tile[PAD(j)];
    }
}
