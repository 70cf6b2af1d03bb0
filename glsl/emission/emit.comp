#version 450
// Emit (seed 002, Algorithm 1), one invocation per particle slot (life attribute: x =
// age in seconds, negative for a dead slot; y = 1 for a permanent particle, which never
// ages). A live slot ages by the step; past the life limit, or dead, it is due: while
// this step's budget lasts it is born at a random source s (a covered texel of the UV
// position buffers, or a vertex) at tau in (tau_lo, tau_hi) between the last frame's
// surface point and this frame's, with velocity k (post - prev) / (t_post - t_prev) about
// tau (eq. 7: k = transfer / frame time, so transfer 1 gives the surface's own velocity)
// and an age drawn in (0, limit / 2); a due slot without budget dies (pos.w = -1, which
// the neighbour keys sort last). Bindings: EmitIo in src/sim/emission/emit.rs; EmitParams
// mirrors EmitGpuParams there.
#include "common/index.glsl"
struct EmitParams {
    uint n;            // particle slots
    uint sources;      // covered texels or vertices
    uint budget;       // births this step at most
    uint seed;         // per step
    float limit;       // life limit (seconds)
    float dt;          // step (seconds)
    float dtau;        // half the finite-difference interval in tau
    float k;           // transfer / frame time (1/s)
    float tau_lo;      // this step's share of the frame interval
    float tau_hi;
    float frame_dt;    // seconds between the two source frames
    float jitter;      // births moved this far in a random direction (coincident births)
};
layout(std430, binding = EMIT_B_PARAMS) readonly buffer Params { EmitParams E; };
layout(std430, binding = EMIT_B_CUR) readonly buffer Cur { vec4 cur[]; };    // Position_t
layout(std430, binding = EMIT_B_PREV) readonly buffer Prev { vec4 prev[]; };  // Position_{t-dt}
layout(std430, binding = EMIT_B_VALID) readonly buffer Valid { uint valid[]; };  // sources
layout(std430, binding = EMIT_B_POS) buffer Pos { vec4 pos[]; };
layout(std430, binding = EMIT_B_VEL) buffer Vel { vec4 vel[]; };
layout(std430, binding = EMIT_B_VHALF) buffer Vhalf { vec4 vhalf[]; };
layout(std430, binding = EMIT_B_LIFE) buffer Life { vec4 life[]; };
// This step: x due slots, y slots alive after it, z birth requests (births = min(z, budget)).
layout(std430, binding = EMIT_B_COUNTS) buffer Counts { uvec4 counts; };
// Since the host last cleared it: x births, y summed speed at birth, z summed surface
// speed at the birth points (both in cm/s).
layout(std430, binding = EMIT_B_STATS) buffer Stats { uvec4 stats; };
// Births per emitting primitive (layout triangle for uv, vertex for vertices).
layout(std430, binding = EMIT_B_HIST) buffer Hist { uint hist[]; };

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
    vec4 L = life[i];
    if (L.y > 0.5) {  // permanent
        atomicAdd(counts.y, 1u);
        return;
    }
    if (L.x >= 0.0 && L.x + E.dt <= E.limit) {
        life[i].x = L.x + E.dt;
        atomicAdd(counts.y, 1u);
        return;
    }
    atomicAdd(counts.x, 1u);
    if (E.sources > 0u && atomicAdd(counts.z, 1u) < E.budget) {
        uint h = pcg(i ^ pcg(E.seed));
        uint s = valid[h % E.sources];
        h = pcg(h);
        float tau = mix(E.tau_lo, E.tau_hi, unit(h));
        h = pcg(h);
        float t0 = max(tau - E.dtau, 0.0), t1 = min(tau + E.dtau, 1.0);
        vec3 p = at(s, tau);
        vec3 dir = vec3(unit(pcg(h ^ 1u)), unit(pcg(h ^ 2u)), unit(pcg(h ^ 3u))) * 2.0 - 1.0;
        p += E.jitter * dir;
        vec3 v = E.k * (at(s, t1) - at(s, t0)) / (t1 - t0);
        pos[i] = vec4(p, 0.0);
        vel[i] = vec4(v, 0.0);
        vhalf[i] = vec4(v, 0.0);
        life[i] = vec4(unit(h) * 0.5 * E.limit, 0.0, 0.0, 0.0);
        atomicAdd(counts.y, 1u);
        atomicAdd(stats.x, 1u);
        atomicAdd(stats.y, uint(length(v) * 100.0 + 0.5));
        float surface = E.frame_dt > 0.0 ? length(cur[s].xyz - prev[s].xyz) / E.frame_dt : 0.0;
        atomicAdd(stats.z, uint(surface * 100.0 + 0.5));
#if EMIT_UV
        atomicAdd(hist[uint(cur[s].w) - 1u], 1u);
#else
        atomicAdd(hist[s], 1u);
#endif
    } else if (L.x >= 0.0 || pos[i].w >= 0.0) {
        life[i].x = -1.0;  // dies: sorted last, skipped by every pass, not drawn
        pos[i].w = -1.0;
        vel[i] = vec4(0.0);
        vhalf[i] = vec4(0.0);
    }
}
