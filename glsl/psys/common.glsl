// GPU particle systems (seed 003): the system's parameters, the counters and helpers.
// Mirrors src/sim/psys/gpu.rs (SystemParams, Counters); one source of truth for the layout.
#ifndef PSYS_COMMON_GLSL
#define PSYS_COMMON_GLSL
// Limits, force, collider and emitter kinds, integrators, event flags and kinds, NO_SLOT:
// generated from src/sim/psys/codes.rs.
#include "generated/psys_codes.glsl"

struct Force {
    vec4 a;  // attractor: xyz point, w kind | vortex: xyz centre | curl: -
    vec4 b;  // attractor: x strength (< 0 repels), y eps | vortex: xyz axis, w strength |
             // curl: x strength, y scale (1/m), z speed (1/s)
};
struct Collider {
    vec4 a;  // plane: xyz normal, w kind | sphere: xyz centre | box: xyz min | capsule: xyz end 0
    vec4 b;  // plane: x offset | sphere: x radius | box: xyz max | capsule: xyz end 1, w radius
    vec4 c;  // x restitution, y friction, z inside (1: keep inside), w kill on hit (1)
};
struct SystemParams {
    vec4 emitter;       // xyz centre, w shape
    vec4 extent;        // box half extents xyz; sphere and disc radius x; w surface only (1)
    vec4 normal;        // disc normal
    vec4 offset_mean;   // position offset
    vec4 offset_var;
    vec4 vel_mean;      // w: cone half-angle (rad) the direction is spread over
    vec4 vel_var;
    vec4 color_mean;    // rgba (a: opacity)
    vec4 color_var;
    vec4 scalar_mean;   // x size (m), y life (s)
    vec4 scalar_var;
    vec4 gravity;       // xyz
    vec4 wind;          // xyz wind velocity, w drag per second toward it
    vec4 death;         // x damping per second, y max distance from the source (0: off),
                        // z die out of view (1), w type id
    uvec4 counts;       // x forces, y colliders, z size keys, w colour keys
    uvec4 counts2;      // x opacity keys, y integrator, z event flags (EV_*), w -
    vec4 size_keys[MAX_KEYS];     // x life fraction, y factor
    vec4 color_keys[MAX_KEYS];    // rgb factor, w life fraction
    vec4 opacity_keys[MAX_KEYS];  // x life fraction, y factor
    Force forces[MAX_FORCES];
    Collider colliders[MAX_COLLIDERS];
    // Boids (grid_dims.w = 1): [0] x perception radius, y separation radius, z max speed,
    // w max steering acceleration | [1] weights: x separation, y alignment, z cohesion,
    // w avoidance | [2] the neighbour grid's origin xyz, cell w | [3] x look-ahead (s),
    // y min speed
    vec4 boids[4];
    uvec4 grid_dims;    // xyz cells, w boids on (1)
};
struct Counters {
    int dead_count;     // free slots on the dead stack (stateful)
    uint alive[2];      // alive-list lengths (ping-pong)
    uint verts;         // vertices per particle of the draw
    uint update_args[4];  // VkDispatchIndirectCommand over the alive list (+ pad)
    // VkDrawIndirectCommand: verts x drawn vertices in one instance (llvmpipe runs
    // instances one by one, so particles are not instances)
    uint draw_args[4];
    uint births;
    uint refused;       // births refused: no free slot (the budget)
    uint died_life;
    uint died_view;
    uint died_distance;
    uint died_collision;
    uint overwritten;   // closed form: live particles overwritten by the ring (the budget)
    uint changed;       // parents that died by a collision event (changed type)
    uint spawned;       // births from events
    uint spawn_refused; // children refused: no free slot
    uint events_dropped;  // events lost: the event list was full
    uint pad;
};
// An event record: xyz where, w kind | xyz the parent's velocity | xyz contact normal.
struct Event {
    vec4 p;
    vec4 v;
    vec4 n;
};

// PCG hash (Jarzynski & Olano 2020): a uniform u32 per input.
uint pcg(uint v) {
    uint s = v * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}
// Uniform in [0, 1) from a stream state that advances.
float rnd(inout uint s) { s = pcg(s); return float(s >> 8) * (1.0 / 16777216.0); }
// Uniform in [-1, 1).
float srnd(inout uint s) { return 2.0 * rnd(s) - 1.0; }
vec3 srnd3(inout uint s) { return vec3(srnd(s), srnd(s), srnd(s)); }
vec4 srnd4(inout uint s) { return vec4(srnd(s), srnd(s), srnd(s), srnd(s)); }

// Piecewise-linear keyframes over life, read in place from the parameter block `sp`
// (passing the arrays to a function would copy them per vertex). CURVE1: keys with x the
// life fraction, y the value; CURVE3: rgb with w the life fraction. 1 without keys.
#define CURVE1(keys, n, u, out_v) {                                                    \
    out_v = 1.0;                                                                       \
    if (n > 0u) {                                                                      \
        out_v = keys[n - 1u].y;                                                        \
        if (u <= keys[0].x) out_v = keys[0].y;                                         \
        else for (uint k_ = 1u; k_ < n; k_++) {                                        \
            if (u <= keys[k_].x) {                                                     \
                float t_ = (u - keys[k_ - 1u].x) / max(keys[k_].x - keys[k_ - 1u].x, 1e-6); \
                out_v = mix(keys[k_ - 1u].y, keys[k_].y, t_);                           \
                break;                                                                 \
            }                                                                          \
        }                                                                              \
    }                                                                                  \
}
#define CURVE3(keys, n, u, out_v) {                                                    \
    out_v = vec3(1.0);                                                                 \
    if (n > 0u) {                                                                      \
        out_v = keys[n - 1u].xyz;                                                      \
        if (u <= keys[0].w) out_v = keys[0].xyz;                                       \
        else for (uint k_ = 1u; k_ < n; k_++) {                                        \
            if (u <= keys[k_].w) {                                                     \
                float t_ = (u - keys[k_ - 1u].w) / max(keys[k_].w - keys[k_ - 1u].w, 1e-6); \
                out_v = mix(keys[k_ - 1u].xyz, keys[k_].xyz, t_);                       \
                break;                                                                 \
            }                                                                          \
        }                                                                              \
    }                                                                                  \
}
#endif
