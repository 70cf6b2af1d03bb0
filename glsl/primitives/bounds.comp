#version 450
// Min/max of vec4 positions (xyz): pass 0 reduces each block of WG * ITEMS positions to a
// (min, max) pair; pass 1 (one workgroup) reduces those pairs to the final box.
#include "common/index.glsl"
layout(constant_id = 1) const uint ITEMS = 8;
layout(std430, binding = BOUNDS_B_SRC) readonly buffer Src{ vec4 src[]; };  // positions or pairs
layout(std430, binding = BOUNDS_B_DST) writeonly buffer Dst{ vec4 dst[]; };  // (min, max) pairs
layout(push_constant) uniform Push { uint n; uint pairs; } pc;    // pairs: src holds pairs
const float BIG = 3.402823e38;
shared vec3 s_min[gl_WorkGroupSize.x];
shared vec3 s_max[gl_WorkGroupSize.x];
void main() {
    uint wg = gl_WorkGroupSize.x;
    uint lid = gl_LocalInvocationIndex;
    vec3 lo = vec3(BIG), hi = vec3(-BIG);
    if (pc.pairs == 0u) {
        uint base = group_id() * wg * ITEMS;
        for (uint k = 0; k < ITEMS; ++k) {
            uint i = base + k * wg + lid;
            if (i < pc.n) { vec3 p = src[i].xyz; lo = min(lo, p); hi = max(hi, p); }
        }
    } else {
        for (uint i = lid; i < pc.n; i += wg) {
            lo = min(lo, src[2 * i].xyz);
            hi = max(hi, src[2 * i + 1].xyz);
        }
    }
    s_min[lid] = lo;
    s_max[lid] = hi;
    barrier();
    for (uint s = wg / 2; s > 0; s >>= 1) {
        if (lid < s) {
            s_min[lid] = min(s_min[lid], s_min[lid + s]);
            s_max[lid] = max(s_max[lid], s_max[lid + s]);
        }
        barrier();
    }
    if (lid == 0) {
        dst[2 * group_id()] = vec4(s_min[0], 0.0);
        dst[2 * group_id() + 1] = vec4(s_max[0], 0.0);
    }
}
