#version 450
// The end of one pressure-solve iteration, one workgroup: the iteration pass's partials
// into the mean error, the iteration count, and the stop decision (at least min_iter, at
// most max_iter, else until the mean is within the target). Stopping zeroes the indirect
// dispatch of the remaining recorded iterations: no read-back per iteration.
// DIVERGENCE: 1 for DFSPH's divergence solve, 0 for the density solve.
#include "pressure.glsl"
void main() {
    if (S.done != 0u) return;  // the same for the whole workgroup
    uint lid = gl_LocalInvocationIndex;
    uint parts = (pc.n + PARTICLE_WG - 1u) / PARTICLE_WG;
    vec3 a = vec3(0.0);
    for (uint k = lid; k < parts; k += gl_WorkGroupSize.x) {
        vec3 p = partials[k].xyz;
        a = vec3(a.x + p.x, max(a.y, p.y), a.z + p.z);
    }
    red_s[lid] = a;
    barrier();
    for (uint h = gl_WorkGroupSize.x / 2u; h > 0u; h >>= 1u) {
        if (lid < h) {
            vec3 o = red_s[lid + h];
            red_s[lid] = vec3(red_s[lid].x + o.x, max(red_s[lid].y, o.y), red_s[lid].z + o.z);
        }
        barrier();
    }
    if (lid != 0u) return;
    float mean = red_s[0].x / max(red_s[0].z, 1.0);
    uint it = S.iter + 1u;
    S.iter = it;
#if DIVERGENCE
    float target = P.divergence_target;
    S.divergence_iters = it;
    S.divergence_err = mean;
#else
    float target = P.density_target;
    S.density_iters = it;
    S.density_err = mean;
#endif
    if ((it >= P.min_iter && mean <= target) || it >= P.max_iter) {
        S.done = 1u;
        S.gz = 0u;
    }
}
