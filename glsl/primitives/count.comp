#version 450
// Counting sort pass 1 (seed 002): count keys per cell with atomicAdd; each element keeps
// the returned in-cell rank. Keys >= cells are clamped to the last cell and counted in
// counts[cells] so the output is still a permutation and the misuse is reported.
#include "common/index.glsl"
layout(std430, binding = COUNT_B_KEYS) readonly buffer Keys { uint keys[]; };  // cell keys
layout(std430, binding = COUNT_B_COUNTS) buffer Counts { uint counts[]; };  // cells + 1
layout(std430, binding = COUNT_B_RANK) writeonly buffer Rank { uint rank[]; };  // in-cell rank
layout(push_constant) uniform Push { uint n; uint cells; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    uint k = keys[i];
    if (k >= pc.cells) { atomicAdd(counts[pc.cells], 1u); k = pc.cells - 1u; }
    rank[i] = atomicAdd(counts[k], 1u);
}
