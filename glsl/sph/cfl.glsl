// The CFL step limit's reduction (src/sim/sph/cfl.rs), shared by cfl.comp (at a step's
// start) and euler.comp (at a step's end, for the next step): each workgroup's largest
// |v|^2 into clock.vmax2 (one atomicMax of its bits: non-negative floats order like their
// bits, so the result is order-free), and the last workgroup of the pass to arrive takes
// dt = min(dt_max, cfl h / max(v_max, speed)). Euler's dt is the next step's; a cfl.comp
// run after it (the parameters were uploaded again) finds `fresh` and keeps its previous
// step's dt. Include after common/index.glsl with CFL_CLOCK defined as the clock's binding,
// and CFL_REDUCE defined where the pass reduces (the clock alone otherwise).
#ifndef SPH_CFL_GLSL
#define SPH_CFL_GLSL
struct ClockState {
    uint vmax2;    // float bits of the largest |v|^2, 0 between reductions
    float dt;      // the dt of the step that runs next or now (0 before the first)
    float prev;    // the dt of the step before it
    uint fresh;    // 1: dt was set at the last step's end (euler.comp), prev is that step's
    uint arrived;  // workgroups of the reducing pass that have arrived
    uint pad0, pad1, pad2;
};
layout(std430, binding = CFL_CLOCK) coherent buffer Clock { ClockState clock; };
#endif

#if defined(CFL_REDUCE) && !defined(SPH_CFL_REDUCE_GLSL)
#define SPH_CFL_REDUCE_GLSL
shared float cfl_s[gl_WorkGroupSize.x];
shared bool cfl_last;

// Every invocation of the workgroup calls it with its largest |v|^2 (0 if none), `parts`
// the pass's workgroups (a y-split dispatch's spare groups return first). Returns true in
// invocation 0 of the last workgroup to arrive, with the step's dt and its previous
// step's (at_end: the pass ends a step, so dt is the next step's).
bool cfl_reduce(float v2, uint parts, vec4 limit, bool at_end, out float dt, out float prev) {
    uint lid = gl_LocalInvocationIndex;
    dt = 0.0;
    prev = 0.0;
    cfl_s[lid] = v2;
    barrier();
    for (uint s = gl_WorkGroupSize.x / 2u; s > 0u; s >>= 1u) {
        if (lid < s) cfl_s[lid] = max(cfl_s[lid], cfl_s[lid + s]);
        barrier();
    }
    if (group_id() >= parts) return false;
    if (lid == 0u) {
        atomicMax(clock.vmax2, floatBitsToUint(cfl_s[0]));
        memoryBarrierBuffer();
        cfl_last = atomicAdd(clock.arrived, 1u) == parts - 1u;
    }
    barrier();
    if (lid != 0u || !cfl_last) return false;
    memoryBarrierBuffer();
    // limit: (cfl, h, dt_max, the least speed the limit divides by)
    float v = max(sqrt(uintBitsToFloat(atomicOr(clock.vmax2, 0u))), max(limit.w, 1e-6));
    dt = min(limit.z, limit.x * limit.y / v);
    float last = clock.fresh != 0u && !at_end ? clock.prev : clock.dt;
    prev = last > 0.0 ? last : dt;
    clock.vmax2 = 0u;
    clock.arrived = 0u;
    clock.dt = dt;
    clock.prev = prev;
    clock.fresh = at_end ? 1u : 0u;
    return true;
}
#endif
