#version 450
// The density error of a step (src/sim/sph/errors.rs): per live particle (pos.w >= 0)
// e = max(rho / rho0 - 1, 0), compression only (surface particles lack neighbours, as in
// SPlisHSPlasH's solvers). Two levels: mode 0 reduces each block of WG * ITEMS particles to
// a (sum, max, count) partial; mode 1 (one workgroup) reduces the partials into
// records[2 step] = (mean, max, count, dt: the step's, as the parameters hold it) and copies the pressure solve's iterations and
// errors into records[2 step + 1] (SolveState in sph/pressure.glsl; zeros for wcsph).
#include "common/index.glsl"
#include "common/reduce.glsl"
layout(constant_id = 1) const uint ITEMS = 8;
layout(std430, binding = SERR_B_POS) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = SERR_B_RHO_P) readonly buffer RhoP { vec2 rho_p[]; };
layout(std430, binding = SERR_B_PARTIALS) buffer Partials { vec4 partials[]; };
layout(std430, binding = SERR_B_RECORDS) buffer Records { vec4 records[]; };
layout(std430, binding = SERR_B_PARAMS) readonly buffer Params { vec4 gravity; } params;  // w = dt
layout(std430, binding = SERR_B_SOLVE) readonly buffer Solve {
    uvec4 args_iter;
    uvec4 done_pad;
    uvec2 iters;  // density, divergence
    vec2 errs;    // density, divergence
} solve;
layout(push_constant) uniform Push {
    uint n;      // mode 0: particles; mode 1: partials
    uint mode;
    uint step;   // the record written in mode 1
    float rest_density;
} pc;
void main() {
    uint wg = gl_WorkGroupSize.x, lid = gl_LocalInvocationIndex;
    vec3 acc = vec3(0.0);
    if (pc.mode == 0u) {
        uint base = group_id() * wg * ITEMS;
        for (uint k = 0u; k < ITEMS; ++k) {
            uint i = base + k * wg + lid;
            if (i >= pc.n || pos[i].w < 0.0) continue;
            float e = max(rho_p[i].x / pc.rest_density - 1.0, 0.0);
            acc += vec3(e, 0.0, 1.0);
            acc.y = max(acc.y, e);
        }
    } else {
        for (uint i = lid; i < pc.n; i += wg) {
            acc = combine(acc, partials[i].xyz);
        }
    }
    vec3 s = reduce_workgroup(acc);  // sum, max, count
    if (lid != 0u) return;
    if (pc.mode == 0u) partials[group_id()] = vec4(s, 0.0);
    else {
        records[2u * pc.step] = vec4(s.x / max(s.z, 1.0), s.y, s.z, params.gravity.w);
        records[2u * pc.step + 1u] = vec4(uintBitsToFloat(solve.iters.x),
                                          uintBitsToFloat(solve.iters.y), solve.errs);
    }
}
