#version 450
// Scan pass 1 (reduce-then-scan): the sum of each block of WG * ITEMS elements.
#include "common/index.glsl"
#include "workgroup.glsl"
layout(constant_id = 1) const uint ITEMS = 8;
layout(std430, binding = 0) readonly buffer In { uint data[]; };  // binding 0: this segment
layout(std430, binding = 1) buffer Sums { uint sums[]; };          // binding 1: block sums
layout(push_constant) uniform Push { uint n; uint block_base; uint flags; } pc;
void main() {
    uint wg = gl_WorkGroupSize.x;
    uint base = group_id() * wg * ITEMS;
    uint s = 0;
    for (uint k = 0; k < ITEMS; ++k) {
        uint i = base + k * wg + gl_LocalInvocationIndex;  // coalesced
        if (i < pc.n) s += data[i];
    }
    uint total = wg_reduce(s);
    if (gl_LocalInvocationIndex == 0) sums[pc.block_base + group_id()] = total;
}
