// The pressure solvers' shared part (src/sim/sph/pressure.rs): PressureIo's bindings past
// SphIo's, the iteration state, the kernel and its gradient, and the iteration's error
// reduction: per workgroup, then (CHECK) in the last workgroup to finish, which decides
// whether the solve goes on. V = m / rho0 throughout.
// START_SOLVE: the pass before a solve's iterations, which starts the solve's state.
// CHECK: the pass that reduces an iteration's error ends the iteration.
#ifndef SPH_PRESSURE_GLSL
#define SPH_PRESSURE_GLSL
#include "common.glsl"
layout(std430, binding = SPH_B_AUX) buffer Aux { vec4 aux[]; };     // per solver, see its passes
layout(std430, binding = SPH_B_AUX2) buffer Aux2 { vec4 aux2[]; };
layout(std430, binding = SPH_B_PARTIALS) coherent buffer Partials { vec4 partials[]; };  // (sum, max, count)
struct SolveState {
    uint gx, gy, gz;   // the iteration passes' VkDispatchIndirectCommand; gz 0 once done
    uint iter;         // iterations of the current solve
    uint done;
    uint arrived;      // workgroups of the checking pass that have written their partials
    uint pad0, pad1;
    uint density_iters, divergence_iters;
    float density_err, divergence_err;  // the solve's own estimate at its last iteration
};
layout(std430, binding = SPH_B_SOLVE) coherent buffer Solve { SolveState S; };
// DFSPH's neighbour lists of the step (FACTOR writes them; positions stay put until euler):
// nb_list[i] = the count, nb_list[(k + 1) n + i] = the k-th neighbour (j != i, r < h), in
// the grid search's order, so a list visit sums exactly as the search would.
layout(std430, binding = SPH_B_NB_LIST) buffer NbList { uint nb_list[]; };
layout(std430, binding = SPH_B_OVERFLOW) buffer Overflow { uint list_overflows; };
// The CFL clock, and the parameters again, writable: euler.comp sets the next step's dt
// once every workgroup has read this step's (cfl.glsl).
#define CFL_CLOCK SPH_B_CLOCK
#include "cfl.glsl"
layout(std430, binding = SPH_B_PARAMS_OUT) buffer ParamsOut { SphParams PO; };

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

// Start a solve (invocation 0 of the pass before its iterations; see SOLVE_START): the
// iteration passes' group counts for pc.n particles (split over y past 65535, as
// ComputePipeline::dispatch_groups), no iteration yet.
void start_solve() {
    uint groups = max((pc.n + PARTICLE_WG - 1u) / PARTICLE_WG, 1u);
    uint gx = min(groups, 65535u);
    S.gx = gx;
    S.gy = (groups + gx - 1u) / gx;
    S.gz = 1u;
    S.iter = 0u;
    S.done = 0u;
    S.arrived = 0u;
}
#if START_SOLVE
#define SOLVE_START() if (global_id() == 0u) start_solve();
#else
#define SOLVE_START()
#endif

// The end of an iteration, by every invocation of the last workgroup to write its
// partial: the partials into the mean error, the iteration count, and the stop decision
// (at least min_iter, at most max_iter, else until the mean is within the target).
// Stopping zeroes the group count of the iteration passes recorded after this one: no
// read-back per iteration. The partials are summed in the order a 2 WG-wide workgroup
// would (lane l takes l and l + WG): the same mean, bit for bit, as the one-workgroup
// loop pass this replaced, so the same iteration counts.
void finish_iteration(uint parts) {
    uint lid = gl_LocalInvocationIndex, wg = gl_WorkGroupSize.x;
    vec3 a = vec3(0.0), b = vec3(0.0);
    for (uint k = lid; k < parts; k += 2u * wg) a = combine(a, partials[k].xyz);
    for (uint k = lid + wg; k < parts; k += 2u * wg) b = combine(b, partials[k].xyz);
    vec3 r = reduce_workgroup(combine(a, b));
    if (lid != 0u) return;
    S.arrived = 0u;
    float mean = r.x / max(r.z, 1.0);
    uint it = S.iter + 1u;
    S.iter = it;
#if DIVERGENCE
    float target = P.divergence_target;
    uint least = P.div_min_iter;
#else
    float target = P.density_target;
    uint least = P.min_iter;
#endif
    bool stop = (it >= least && mean <= target) || it >= P.max_iter;
    // The count's top bit: the solve stopped here, so one whose recorded iterations ran
    // out before it stopped is told from one that stopped at the last (src/sim/sph/errors.rs).
    uint count = it | (stop ? 0x80000000u : 0u);
#if DIVERGENCE
    S.divergence_iters = count;
    S.divergence_err = mean;
#else
    S.density_iters = count;
    S.density_err = mean;
#endif
    if (stop) {
        S.done = 1u;
        S.gz = 0u;
    }
}

#if CHECK
shared bool s_last;
#endif

// The workgroup's (sum, max, count) of e over its counted invocations into
// partials[group_id()]; every invocation calls it. CHECK: the last workgroup to do so
// ends the iteration (finish_iteration).
void reduce_error(float e, bool counted) {
    uint parts = (pc.n + PARTICLE_WG - 1u) / PARTICLE_WG;
    vec3 r = reduce_workgroup(counted ? vec3(e, e, 1.0) : vec3(0.0));
    if (group_id() >= parts) return;  // a y-split dispatch's spare groups (uniform)
#if CHECK
    if (gl_LocalInvocationIndex == 0u) {
        partials[group_id()] = vec4(r, 0.0);
        memoryBarrierBuffer();
        s_last = atomicAdd(S.arrived, 1u) == parts - 1u;
    }
    barrier();
    if (s_last) {
        memoryBarrierBuffer();
        finish_iteration(parts);
    }
#else
    if (gl_LocalInvocationIndex == 0u) partials[group_id()] = vec4(r, 0.0);
#endif
}
#endif
