#version 450
// Emit (seed 002, Algorithm 1), one invocation per particle slot. A slot whose life
// exceeds the limit respawns, while this step's budget lasts, at a random covered texel s
// of the UV position buffers, at tau in (0, 1) between the last frame's surface point and
// this frame's, with velocity k (post - prev) / (2 dtau) (eq. 7: k = transfer / frame
// time, so transfer 1 gives the surface's own velocity) and a new life in
// (0, limit / 2); any other slot ages by the step. Slots waiting for budget keep their
// state; a slot's life is negative until its first birth. Bindings: EmitIo in
// src/emission/emit.rs; EmitParams mirrors EmitGpuParams there.
#include "common/index.glsl"
struct EmitParams {
    uint n;            // particle slots
    uint valid_count;  // covered texels
    uint budget;       // births this step at most
    uint seed;         // per step
    float limit;       // life limit (seconds)
    float dt;          // step (seconds)
    float dtau;        // half the finite-difference interval in tau
    float k;           // transfer / frame time (1/s)
};
layout(std430, binding = EMIT_B_PARAMS) readonly buffer Params { EmitParams E; };
layout(std430, binding = EMIT_B_CUR) readonly buffer Cur { vec4 cur[]; };    // Position_t
layout(std430, binding = EMIT_B_PREV) readonly buffer Prev { vec4 prev[]; };  // Position_{t-dt}
layout(std430, binding = EMIT_B_VALID) readonly buffer Valid { uint valid[]; };
layout(std430, binding = EMIT_B_POS) buffer Pos { vec4 pos[]; };
layout(std430, binding = EMIT_B_VEL) buffer Vel { vec4 vel[]; };
layout(std430, binding = EMIT_B_LIFE) buffer Life { float life[]; };
// x: due slots that asked for a birth this step (births = min(x, budget)), y: slots
// alive after the step (life >= 0).
layout(std430, binding = EMIT_B_COUNTS) buffer Counts { uvec4 counts; };

// PCG hash (O'Neill): a well-mixed 32-bit value per (slot, step, draw).
uint pcg(uint v) {
    uint s = v * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}
float unit(uint h) { return float(h >> 8) * (1.0 / 16777216.0); }  // [0, 1)

vec3 at(uint s, float tau) { return mix(prev[s].xyz, cur[s].xyz, tau); }

void main() {
    uint i = global_id();
    if (i >= E.n) return;
    float l = life[i];
    if (l > E.limit || l < 0.0) {
        if (E.valid_count > 0u && atomicAdd(counts.x, 1u) < E.budget) {
            uint h = pcg(i ^ pcg(E.seed));
            uint s = valid[h % E.valid_count];
            h = pcg(h);
            // tau in (dtau, 1 - dtau): both finite-difference samples on the segment.
            float tau = E.dtau + unit(h) * (1.0 - 2.0 * E.dtau);
            h = pcg(h);
            vec3 p = at(s, tau);
            vec3 post = at(s, tau + E.dtau), pre = at(s, tau - E.dtau);
            pos[i] = vec4(p, 0.0);
            vel[i] = vec4(E.k * (post - pre) / (2.0 * E.dtau), 0.0);
            life[i] = unit(h) * 0.5 * E.limit;
            atomicAdd(counts.y, 1u);
        } else if (l >= 0.0) {
            atomicAdd(counts.y, 1u);  // due, no budget left: alive until a later step
        }
    } else {
        life[i] = l + E.dt;
        atomicAdd(counts.y, 1u);
    }
}
