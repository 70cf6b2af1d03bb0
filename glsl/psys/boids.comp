#version 450
// Boids (Reynolds 1987) on the neighbour grid: each alive particle's steering from the
// flockmates within its perception radius (separation, alignment, cohesion) and from the
// colliders its look-ahead point would touch (avoidance), clamped to the steering limit.
// Reads positions and velocities only, so every boid sees the same frame; the update
// adds the result.
#include "common/index.glsl"
#include "common.glsl"
#include "push.glsl"
#include "collide.glsl"
layout(std430, binding = BOIDS_B_PARAMS) readonly buffer Params { SystemParams sp; };
layout(std430, binding = BOIDS_B_COUNTERS) readonly buffer Counters_ { Counters c; };
layout(std430, binding = BOIDS_B_ALIVE) readonly buffer Alive { uint alive[]; };
layout(std430, binding = BOIDS_B_POS) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = BOIDS_B_VEL) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = BOIDS_B_STEER) writeonly buffer Steer { vec4 steer[]; };
layout(std430, binding = BOIDS_B_PERM) readonly buffer Perm { uint perm[]; };  // sorted -> slot
// The scene character's posed capsules (state.glsl), for avoidance.
layout(std430, binding = BOIDS_B_CAPSULES) readonly buffer Capsules { vec4 capsules[]; };
#define NB_B_KEYS BOIDS_B_NB_KEYS
#define NB_B_START BOIDS_B_NB_START
#define NB_B_END BOIDS_B_NB_END
#define NB_B_BOX BOIDS_B_NB_BOX
#define NB_ORIGIN (sp.boids[2].xyz)
#define NB_CELL (sp.boids[2].w)
#define NB_DIMS (sp.grid_dims.xyz)
#define NB_TABLE 1u
#define NB_N (pc.capacity)
#include "primitives/neighbors.glsl"

vec3 velocity_of(uint slot) {
    vec4 V = vel[slot];
    return sp.counts2.y == I_VERLET ? (pos[slot].xyz - V.xyz) / pc.dt : V.xyz;
}

void main() {
    uint i = global_id();
    if (i >= c.alive[pc.cur]) return;
    uint slot = alive[pc.cur * pc.capacity + i];
    vec3 p = pos[slot].xyz, v = velocity_of(slot);
    float r = sp.boids[0].x, rs = sp.boids[0].y;
    vec3 sep = vec3(0.0), mean_v = vec3(0.0), mean_p = vec3(0.0);
    uint n = 0u;
    NB_BEGIN(p, r, j)
        uint o = perm[j];
        vec4 q = pos[o];
        vec3 d = p - q.xyz;
        float d2 = dot(d, d);
        if (o == slot || q.w < 0.0 || d2 > r * r) continue;
        n++;
        mean_v += velocity_of(o);
        mean_p += q.xyz;
        if (d2 < rs * rs) sep += d / max(d2, 1e-8);  // stronger the closer
    NB_END
    vec4 w = sp.boids[1];
    vec3 a = w.x * sep;
    if (n > 0u) a += w.y * (mean_v / float(n) - v) + w.z * (mean_p / float(n) - p);
    // Avoidance: the point the boid reaches in the look-ahead time, pushed off colliders.
    vec3 ahead = p + v * sp.boids[3].x;
    for (uint k = 0u; k < sp.counts.y; k++) {
        bool body = uint(sp.colliders[k].a.w) == C_CHARACTER;
        for (uint q = 0u; q < (body ? pc.capsules : 1u); q++) {
            Collider col = sp.colliders[k];
            if (body) col = posed_capsule(col, capsules[2u * q], capsules[2u * q + 1u]);
            vec3 x = ahead, nrm;
            if (contact(col, x, nrm)) a += w.w * nrm;
        }
    }
    float amax = sp.boids[0].w, len = length(a);
    if (len > amax) a *= amax / len;
    steer[slot] = vec4(a, float(n));
}
