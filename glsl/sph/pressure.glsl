// The pressure solvers' shared part (src/sim/sph/pressure.rs): PressureIo's bindings past
// SphIo's, the iteration state, the kernel and its gradient, and the per-workgroup error
// reduction the loop pass (solve_loop.comp) finishes. V = m / rho0 throughout.
#ifndef SPH_PRESSURE_GLSL
#define SPH_PRESSURE_GLSL
#include "common.glsl"
layout(std430, binding = SPH_B_AUX) buffer Aux { vec4 aux[]; };     // per solver, see its passes
layout(std430, binding = SPH_B_AUX2) buffer Aux2 { vec4 aux2[]; };
layout(std430, binding = SPH_B_PARTIALS) buffer Partials { vec4 partials[]; };  // (sum, max, count)
struct SolveState {
    uint gx, gy, gz;   // the iteration passes' VkDispatchIndirectCommand; gz 0 once done
    uint iter;             // iterations of the current solve
    uint done;
    uint lx, ly, lz;   // the loop pass's own indirect dispatch (1, 1, 1); lz 0 once done
    uint density_iters, divergence_iters;
    float density_err, divergence_err;  // the solve's own estimate at its last iteration
};
layout(std430, binding = SPH_B_SOLVE) buffer Solve { SolveState S; };
// DFSPH's neighbour lists of the step (FACTOR writes them; positions stay put until euler):
// nb_list[i] = the count, nb_list[(k + 1) n + i] = the k-th neighbour (j != i, r < h), in
// the grid search's order, so a list visit sums exactly as the search would.
layout(std430, binding = SPH_B_NB_LIST) buffer NbList { uint nb_list[]; };
layout(std430, binding = SPH_B_OVERFLOW) buffer Overflow { uint list_overflows; };

// VISIT(j) for every neighbour j of particle I at XI: from its list when it has one that
// holds them all, else by the grid search (VISIT then filters j != I, r < h itself).
#define FOR_NEIGHBORS(I, XI, VISIT) { \
    uint nl_n = P.list_max == 0u ? 0xffffffffu : nb_list[I]; \
    if (nl_n <= P.list_max) { \
        for (uint nl_k = 0u; nl_k < nl_n; ++nl_k) { uint nl_j = nb_list[(nl_k + 1u) * pc.n + (I)]; VISIT(nl_j) } \
    } else { NB_BEGIN(XI, P.h, nl_j) VISIT(nl_j) NB_END } }

bool sph_alive(uint i) { return i < sph_live() && pos[i].w >= 0.0; }
float vol0() { return P.mass / P.rest_density; }

// One kernel for densities and gradients (kernel.glsl's, as the density pass), except
// muller's poly6 with spiky, whose divergence reads about 0.8 of poly6's density change on
// a rest lattice: with it the solves over-correct compression a little.
vec3 grad_w(vec3 d, float r2) { return kernel_grad(d, r2); }

// The velocity the collision response leaves to a particle at x moving with v for dt.
void wall_response(vec3 x, float dt, inout vec3 v) {
    vec3 y = x + dt * v;
    vec3 v2 = v;
    collide(y, v, v2);
}

#include "common/reduce.glsl"

// The workgroup's (sum, max, count) of e over its counted invocations into
// partials[group_id()]; every invocation calls it.
void reduce_error(float e, bool counted) {
    vec3 r = reduce_workgroup(counted ? vec3(e, e, 1.0) : vec3(0.0));
    if (gl_LocalInvocationIndex == 0u) partials[group_id()] = vec4(r, 0.0);
}
#endif
