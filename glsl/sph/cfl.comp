#version 450
// The step's dt from its own velocities (src/sim/sph/cfl.rs), at the step's start: MODE 0,
// each workgroup's largest |v|^2 over ITEMS particles each, one atomicMax of its bits per
// workgroup (non-negative floats order like their bits: order-free); MODE 1, one
// invocation: dt = min(dt_max, cfl h / max(v_max, cfl_speed)) into the parameters (the
// passes read P.gravity.w), the previous step's dt into dt_prev, the clock advanced.
#include "common/index.glsl"
layout(constant_id = 1) const uint ITEMS = 8;
struct ClockState {
    uint vmax2;   // float bits of the largest |v|^2, 0 between steps
    float dt;     // the last step's dt (0 before the first)
    float t;      // simulated time
    uint steps;
};
// SphParams' head (common.glsl), then its other fields as floats (a struct member would
// round the head up to 64 bytes).
layout(std430, binding = CFL_B_PARAMS) buffer Params {
    vec4 gravity;     // w = dt
    vec4 domain_min;
    vec4 domain_max;
    float h;
    float rest[];
} P;
layout(std430, binding = CFL_B_POS) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = CFL_B_VEL) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = CFL_B_CLOCK) buffer Clock { ClockState clock; };
layout(push_constant) uniform Push {
    uint n;          // live particles
    uint mode;
    float cfl;
    float dt_max;
    float speed;     // the least speed the limit divides by
    uint dt_prev;    // float index of dt_prev in rest[] (SphGpuParams)
} pc;
shared float red[gl_WorkGroupSize.x];
void main() {
    uint lid = gl_LocalInvocationIndex;
    if (pc.mode == 0u) {
        float m = 0.0;
        uint base = group_id() * gl_WorkGroupSize.x * ITEMS;
        for (uint k = 0u; k < ITEMS; ++k) {
            uint i = base + k * gl_WorkGroupSize.x + lid;
            if (i < pc.n && pos[i].w >= 0.0) { vec3 v = vel[i].xyz; m = max(m, dot(v, v)); }
        }
        red[lid] = m;
        barrier();
        for (uint s = gl_WorkGroupSize.x / 2u; s > 0u; s >>= 1u) {
            if (lid < s) red[lid] = max(red[lid], red[lid + s]);
            barrier();
        }
        if (lid == 0u) atomicMax(clock.vmax2, floatBitsToUint(red[0]));
        return;
    }
    if (lid != 0u) return;
    float v = max(sqrt(uintBitsToFloat(clock.vmax2)), max(pc.speed, 1e-6));
    float dt = min(pc.dt_max, pc.cfl * P.h / v);
    P.rest[pc.dt_prev] = clock.dt > 0.0 ? clock.dt : dt;
    P.gravity.w = dt;
    clock.vmax2 = 0u;
    clock.dt = dt;
    clock.t += dt;
    clock.steps += 1u;
}
