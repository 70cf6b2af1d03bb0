// Control particles (seed 000, 3.1): the SPH bindings (as CTL_B_* numbers) and the control
// set, sorted by its own grid (cells of h_c / 2; sums and field on cells of h_c). Bindings: ControlIo in
// src/sim/control/force.rs; ControlParams mirrors ControlGpuParams there (offsets tested).
#ifndef CONTROL_COMMON_GLSL
#define CONTROL_COMMON_GLSL
#define SPH_B_PARAMS CTL_B_PARAMS
#define SPH_B_NB_KEYS CTL_B_NB_KEYS
#define SPH_B_NB_START CTL_B_NB_START
#define SPH_B_NB_END CTL_B_NB_END
#define SPH_B_NB_BOX CTL_B_NB_BOX
#define SPH_B_POS CTL_B_POS
#define SPH_B_VEL CTL_B_VEL
#define SPH_B_RHO_P CTL_B_RHO_P
#define SPH_B_ACC CTL_B_ACC
#define SPH_B_VHALF CTL_B_VHALF
#define SPH_B_COLLIDERS CTL_B_COLLIDERS
#include "../sph/common.glsl"

struct ControlParams {
    vec4 grid;        // xyz control-grid origin, w = cell (= h_c)
    uvec4 dims;       // xyz control-grid cells, w = control particles m
    float pressure;   // c_cp
    float radius;     // h_c
    float spiky_grad; // -45 / (pi h_c^6)
    float velocity;   // K of the velocity term (0: off, the thesis)
    uint adaptive;    // ADAPTIVE_OFF | ADAPTIVE_ON | ADAPTIVE_SMOOTH
    float low;        // below low * rho0: x up (0.8, 2)
    float high;       // above high * rho0: x down (1.2, 0.5)
    float up;
    float down;
    float inv_frame;  // 1 / frame time: control velocity from two poses
    uint group;       // controlled group, or 0xFFFFFFFF: all
    uint live;        // control particles this step (rays: the GPU's count)
    float attraction; // deficit attraction (m/s^2, 0: off)
    float reach;      // its reach and the damping's (metres) ...
    uint reach_cells; // ... in control-grid cells
    float damping;    // damping relative to the character's velocity (1/s, 0: off)
};
layout(std430, binding = CTL_B_CONTROL) readonly buffer Control { ControlParams C; };
layout(std430, binding = CTL_B_CPOS) readonly buffer Cpos { vec4 cpos[]; };    // sorted, xyz; w: shape's fill
layout(std430, binding = CTL_B_CPREV) readonly buffer Cprev { vec4 cprev[]; };  // previous pose
layout(std430, binding = CTL_B_CRHO) buffer Crho { float crho[]; };  // fluid density there
// Per control particle (density.comp): xyz its velocity, w its eq. 7 weight.
layout(std430, binding = CTL_B_CVW) buffer Cvw { vec4 cvw[]; };
layout(std430, binding = CTL_B_CSTART) readonly buffer Cstart { uint cstart[]; };
layout(std430, binding = CTL_B_CCOUNT) readonly buffer Ccount { uint ccount[]; };
layout(std430, binding = CTL_B_ATTR) readonly buffer Attr { vec4 attr[]; };     // rgb, w = group
// Per control-grid cell (aggregate.comp): deficit-weighted centre, sum of deficits; centre,
// count; sum v.
layout(std430, binding = CTL_B_CAGG) buffer Cagg { vec4 cagg[]; };
// Per cell centre (field.comp): attraction acceleration; mean character velocity, mask.
layout(std430, binding = CTL_B_CFIELD) buffer Cfield { vec4 cfield[]; };
// Per fluid particle (--control-every K > 1): eq. 7's sum and the velocity term's mean
// control velocity (w = 1 where some control particle lies within h_c) of the last refresh.
layout(std430, binding = CTL_B_CFORCE) buffer Cforce { vec4 cforce[]; };
layout(std430, binding = CTL_B_CVMEAN) buffer Cvmean { vec4 cvmean[]; };

// The control set is sorted on a grid of half the cells (h_c / 2, same origin, twice the
// dims: ControlGpu::fine), numbered x fastest, so a run of cells along x is one contiguous
// range of the sorted set; aggregates and the field stay on cells of h_c.
float fine_cell() { return 0.5 * C.grid.w; }
uvec3 fine_dims() { return 2u * C.dims.xyz; }
uint fine_id(ivec3 f) { uvec3 d = fine_dims(); return (uint(f.z) * d.y + uint(f.y)) * d.x + uint(f.x); }
// The cells along x (unclamped: x0 > x1 when none) of the row (y, z) = `yz` of a grid of
// `cell`-sized cells that hold points within `r` of `x`: the sphere's chord in that row.
ivec2 row_span(vec3 x, ivec2 yz, float cell, float r) {
    vec2 lo = C.grid.yz + vec2(yz) * cell;
    vec2 e = max(max(lo - x.yz, x.yz - lo - cell), vec2(0.0));
    float rem = r * r - dot(e, e);
    if (rem <= 0.0) return ivec2(1, 0);
    float half_chord = sqrt(rem);
    return ivec2(floor((x.x - half_chord - C.grid.x) / cell), floor((x.x + half_chord - C.grid.x) / cell));
}
// The sorted slots of fine cells a .. b (ids a <= b): [start, end).
uvec2 fine_range(uint a, uint b) { return uvec2(cstart[a], cstart[b] + ccount[b]); }

const uint ALL_GROUPS = 0xFFFFFFFFu;
bool controlled(uint i) { return C.group == ALL_GROUPS || floatBitsToUint(attr[i].w) == C.group; }

// A control particle's velocity: from its previous pose (inv_frame > 0) or from its pose a
// frame ahead (skin motion: cprev holds that pose and inv_frame < 0).
vec3 control_velocity(uint j) { return (cpos[j].xyz - cprev[j].xyz) * C.inv_frame; }

// Adaptive control pressure (3.1.2) from the fluid density at a control particle.
float adaptive_factor(float rho) {
    float f = rho / P.rest_density;
#if ADAPTIVE == ADAPTIVE_ON
    return f < C.low ? C.up : (f > C.high ? C.down : 1.0);
#elif ADAPTIVE == ADAPTIVE_SMOOTH
    // Ours: the pull fades continuously as the particle fills: up below low, none above
    // high, linear between (1 at the midpoint when up = 2).
    return C.up * clamp((C.high - f) / (C.high - C.low), 0.0, 1.0);
#elif ADAPTIVE == ADAPTIVE_OFF
    return 1.0;
#else
#error "ADAPTIVE names no adaptive mode"
#endif
}
#endif
