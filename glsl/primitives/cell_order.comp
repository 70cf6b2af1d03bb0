#version 450
// Counting sort pass 4: each cell's values in ascending order (insertion sort, one
// invocation per cell). count.comp's in-cell ranks come from atomics, whose order follows
// the scheduling; this makes the permutation (and every sum over a cell's elements in it)
// the same from run to run: (cell, value) order, the values by default the elements'
// indices before the sort.
#include "common/index.glsl"
layout(std430, binding = ORDER_B_COUNTS) readonly buffer Counts { uint counts[]; };
layout(std430, binding = ORDER_B_STARTS) readonly buffer Starts { uint starts[]; };
layout(std430, binding = ORDER_B_SORTED_VALS) buffer SortedVals { uint vals[]; };
layout(push_constant) uniform Push { uint n; uint cells; } pc;
void main() {
    uint c = global_id();
    if (c >= pc.cells) return;
    uint lo = starts[c], hi = min(lo + counts[c], pc.n);
    for (uint i = lo + 1u; i < hi; ++i) {
        uint v = vals[i];
        uint j = i;
        while (j > lo && vals[j - 1u] > v) {
            vals[j] = vals[j - 1u];
            --j;
        }
        vals[j] = v;
    }
}
