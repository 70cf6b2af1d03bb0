#version 450
// Reorder attributes after a sort: dst[i] = src[perm[i]], up to four attributes in one
// dispatch (pc.count of them; the slots past it are bound but not written), so a step's
// reorder reads the permutation once and costs one dispatch and one barrier.
#include "common/index.glsl"
layout(std430, binding = GATHER_B_PERM) readonly buffer Perm { uint perm[]; };  // permutation
layout(std430, binding = GATHER_B_SRC0) readonly buffer Src0 { vec4 src0[]; };  // attributes
layout(std430, binding = GATHER_B_SRC1) readonly buffer Src1 { vec4 src1[]; };
layout(std430, binding = GATHER_B_SRC2) readonly buffer Src2 { vec4 src2[]; };
layout(std430, binding = GATHER_B_SRC3) readonly buffer Src3 { vec4 src3[]; };
layout(std430, binding = GATHER_B_DST0) writeonly buffer Dst0 { vec4 dst0[]; };  // reordered
layout(std430, binding = GATHER_B_DST1) writeonly buffer Dst1 { vec4 dst1[]; };
layout(std430, binding = GATHER_B_DST2) writeonly buffer Dst2 { vec4 dst2[]; };
layout(std430, binding = GATHER_B_DST3) writeonly buffer Dst3 { vec4 dst3[]; };
layout(push_constant) uniform Push { uint n; uint count; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    uint j = perm[i];
    dst0[i] = src0[j];
    if (pc.count > 1u) dst1[i] = src1[j];
    if (pc.count > 2u) dst2[i] = src2[j];
    if (pc.count > 3u) dst3[i] = src3[j];
}
