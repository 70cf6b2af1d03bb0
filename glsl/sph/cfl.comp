#version 450
// The step's dt from its own velocities (src/sim/sph/cfl.rs), at the step's start, in one
// dispatch: each workgroup's largest |v|^2 over ITEMS particles each, the last workgroup
// to arrive sets dt = min(dt_max, cfl h / max(v_max, cfl_speed)) in the parameters (the
// passes read P.gravity.w) and the previous step's dt in dt_prev (cfl.glsl).
#include "common/index.glsl"
layout(constant_id = 1) const uint ITEMS = 8;
#define CFL_CLOCK CFL_B_CLOCK
#define CFL_REDUCE
#include "cfl.glsl"
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
layout(push_constant) uniform Push {
    uint n;          // live particles
    uint parts;      // workgroups of the dispatch
    float cfl;
    float dt_max;
    float speed;     // the least speed the limit divides by
    uint dt_prev;    // float index of dt_prev in rest[] (SphGpuParams)
} pc;
void main() {
    float m = 0.0;
    uint base = group_id() * gl_WorkGroupSize.x * ITEMS;
    for (uint k = 0u; k < ITEMS; ++k) {
        uint i = base + k * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
        if (i < pc.n && pos[i].w >= 0.0) { vec3 v = vel[i].xyz; m = max(m, dot(v, v)); }
    }
    float dt, prev;
    if (cfl_reduce(m, pc.parts, vec4(pc.cfl, P.h, pc.dt_max, pc.speed), false, dt, prev)) {
        P.rest[pc.dt_prev] = prev;
        P.gravity.w = dt;
    }
}
