// A workgroup's (sum, max, count) reduction of per-invocation (sum, max, count) triples:
// the density error's reductions (sph/step_error.comp, sph/pressure.glsl). Include after
// common/index.glsl; every invocation of the workgroup must call it.
#ifndef COMMON_REDUCE_GLSL
#define COMMON_REDUCE_GLSL
shared vec3 red_s[gl_WorkGroupSize.x];
vec3 combine(vec3 a, vec3 b) { return vec3(a.x + b.x, max(a.y, b.y), a.z + b.z); }
vec3 reduce_workgroup(vec3 a) {
    uint lid = gl_LocalInvocationIndex;
    red_s[lid] = a;
    barrier();
    for (uint h = gl_WorkGroupSize.x / 2u; h > 0u; h >>= 1u) {
        if (lid < h) red_s[lid] = combine(red_s[lid], red_s[lid + h]);
        barrier();
    }
    return red_s[0];
}
#endif
