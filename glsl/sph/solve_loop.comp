#version 450
// The end of one pressure-solve iteration, one workgroup: the iteration pass's partials
// into the mean error, the iteration count, and the stop decision (at least min_iter, at
// most max_iter, else until the mean is within the target). Stopping zeroes the indirect
// dispatch of the remaining recorded iterations and of this pass: no read-back per
// iteration, and a converged solve's remaining iterations cost empty dispatches only.
// DIVERGENCE: 1 for DFSPH's divergence solve, 0 for the density solve.
#include "pressure.glsl"
void main() {
    if (S.done != 0u) return;  // the same for the whole workgroup
    uint lid = gl_LocalInvocationIndex;
    uint parts = (pc.n + PARTICLE_WG - 1u) / PARTICLE_WG;
    vec3 a = vec3(0.0);
    for (uint k = lid; k < parts; k += gl_WorkGroupSize.x) {
        a = combine(a, partials[k].xyz);
    }
    vec3 r = reduce_workgroup(a);
    if (lid != 0u) return;
    float mean = r.x / max(r.z, 1.0);
    uint it = S.iter + 1u;
    S.iter = it;
#if DIVERGENCE
    float target = P.divergence_target;
    uint least = P.div_min_iter;
    S.divergence_iters = it;
    S.divergence_err = mean;
#else
    float target = P.density_target;
    uint least = P.min_iter;
    S.density_iters = it;
    S.density_err = mean;
#endif
    if ((it >= least && mean <= target) || it >= P.max_iter) {
        S.done = 1u;
        S.gz = 0u;
        S.lz = 0u;
    }
}
