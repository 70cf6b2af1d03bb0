// The per-slot state and the per-frame push constants every particle-system pass shares.
#ifndef PSYS_STATE_GLSL
#define PSYS_STATE_GLSL
#include "common.glsl"
layout(std430, binding = PSYS_B_PARAMS) readonly buffer Params { SystemParams sp; };
layout(std430, binding = PSYS_B_COUNTERS) buffer Counters_ { Counters c; };
layout(std430, binding = PSYS_B_DEAD) buffer Dead { uint dead[]; };    // free slots (stack)
layout(std430, binding = PSYS_B_ALIVE) buffer Alive { uint alive[]; }; // two lists of capacity
// euler, verlet: xyz position, w age (s) | closed: xyz p0, w birth time (s; < 0: never born)
layout(std430, binding = PSYS_B_POS) buffer Pos { vec4 pos[]; };
// euler: xyz velocity | verlet: xyz previous step's position | closed: xyz v0; w: life span
layout(std430, binding = PSYS_B_VEL) buffer Vel { vec4 vel[]; };
// xyz: position a frame ago (streaks), w: size at birth
layout(std430, binding = PSYS_B_PREV) buffer Prev { vec4 prev[]; };
layout(std430, binding = PSYS_B_COLOR) buffer Color { vec4 color[]; };  // rgba at birth
// keys.comp: sort keys and values (alive slots; NO_SLOT past them).
layout(std430, binding = PSYS_B_KEYS) buffer Keys { uint keys[]; };
layout(std430, binding = PSYS_B_VALS) buffer Vals { uint vals[]; };
// Boids: the steering acceleration of each alive slot (boids.comp), one entry otherwise.
layout(std430, binding = PSYS_B_STEER) buffer Steer { vec4 steer[]; };
// The scene character (a 16-byte stand-in without one): posed capsules, vec4 (a, r) and
// vec4 (b, -) each; skinned positions, triangle indices, cumulative bind-pose areas.
layout(std430, binding = PSYS_B_CAPSULES) readonly buffer Capsules { vec4 capsules[]; };
layout(std430, binding = PSYS_B_MESH_POS) readonly buffer MeshPos { vec4 mesh_pos[]; };
layout(std430, binding = PSYS_B_MESH_IDX) readonly buffer MeshIdx { uint mesh_idx[]; };
layout(std430, binding = PSYS_B_MESH_CDF) readonly buffer MeshCdf { float mesh_cdf[]; };
// Events the update recorded (its own list; the spawn reads the parent system's).
layout(std430, binding = PSYS_B_EVENTS) buffer Events {
    uint ev_count;    // recorded this frame (may pass the list's length: the rest dropped)
    uint ev_args[3];  // the spawn's VkDispatchIndirectCommand
    Event ev[];
};
#include "push.glsl"
#endif
