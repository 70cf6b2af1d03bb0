#version 450
// Reorder an attribute after a sort: dst[i] = src[perm[i]].
#include "common/index.glsl"
layout(std430, binding = GATHER_B_PERM) readonly buffer Perm { uint perm[]; };  // permutation
layout(std430, binding = GATHER_B_SRC) readonly buffer Src { vec4 src[]; };  // attribute
layout(std430, binding = GATHER_B_DST) writeonly buffer Dst { vec4 dst[]; };  // reordered
layout(push_constant) uniform Push { uint n; } pc;
void main() {
    uint i = global_id();
    if (i < pc.n) dst[i] = src[perm[i]];
}
