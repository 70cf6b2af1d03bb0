#version 450
// Counting sort pass 3: element i goes to start[key] + rank: sorted keys and the
// permutation (sorted slot -> value of the element, its original index by default).
#include "common/index.glsl"
layout(std430, binding = SCATTER_B_KEYS) readonly buffer Keys { uint keys[]; };  // keys
layout(std430, binding = SCATTER_B_RANK) readonly buffer Rank { uint rank[]; };  // in-cell rank
layout(std430, binding = SCATTER_B_STARTS) readonly buffer Starts { uint starts[]; };  // cell starts
layout(std430, binding = SCATTER_B_VALS) readonly buffer Vals { uint vals[]; };  // values
layout(std430, binding = SCATTER_B_SORTED_KEYS) writeonly buffer SortedKeys { uint sorted_keys[]; };
layout(std430, binding = SCATTER_B_SORTED_VALS) writeonly buffer SortedVals { uint sorted_vals[]; };
layout(push_constant) uniform Push { uint n; uint cells; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    uint k = min(keys[i], pc.cells - 1u);
    uint dst = starts[k] + rank[i];
    sorted_keys[dst] = k;
    sorted_vals[dst] = vals[i];
}
