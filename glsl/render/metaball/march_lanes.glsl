// Rays marched by several lanes (march.comp, --ray-lanes): RAY_LANES consecutive lanes of
// one subgroup carry one pixel. Every lane holds the pixel's whole path state and computes
// it identically (so the group's control flow stays together); only the samples differ:
// lane j evaluates grid sample i + j of a round, and a ballot over the group gives the
// first crossing. The bisection evaluates a round's 2^L - 1 midpoints at once and replays
// the serial decisions, so every hit is the serial march's; the gradient's terms are split
// among the lanes (march_split.glsl). RAY_LANES 1 is the serial march, one invocation per
// ray.
#ifndef RENDER_METABALL_MARCH_LANES_GLSL
#define RENDER_METABALL_MARCH_LANES_GLSL
#if RAY_LANES == 1
const uint BISECT_LEVELS = 1u;
#elif RAY_LANES == 8
const uint BISECT_LEVELS = 3u;  // 7 midpoints
#elif RAY_LANES == 16
const uint BISECT_LEVELS = 4u;  // 15
#elif RAY_LANES == 32
const uint BISECT_LEVELS = 5u;  // 31
#else
#error "RAY_LANES is 1, 8, 16 or 32"
#endif
const uint LANE_MASK = RAY_LANES == 32 ? 0xFFFFFFFFu : (1u << (RAY_LANES % 32u)) - 1u;

// This invocation's lane in its ray's group, and its group's index in the workgroup
// (consecutive lanes of one subgroup; the host asks for full subgroups of a multiple of
// RAY_LANES). RAY_LANES 1: the workgroup's invocation, as the serial march always laid it.
#if RAY_LANES == 1
uint ray_lane() { return 0u; }
uint ray_group() { return gl_LocalInvocationIndex; }
// The lanes (bit j: lane j) where c holds.
uint lanes_ballot(bool c) { return c ? 1u : 0u; }
uint lanes_max(uint v) { return v; }
vec3 lanes_sum(vec3 v) { return v; }
float lanes_min(float v) { return v; }
float lanes_max(float v) { return v; }
#elif RAY_LANES == 8 || RAY_LANES == 16 || RAY_LANES == 32
uint ray_lane() { return gl_SubgroupInvocationID % RAY_LANES; }
uint ray_group() { return (gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID) / RAY_LANES; }
uint lanes_ballot(bool c) {
    uvec4 b = subgroupBallot(c);
    uint base = gl_SubgroupInvocationID - ray_lane();
    return (b[base >> 5u] >> (base & 31u)) & LANE_MASK;
}
// Reductions over the group by butterfly shuffles (they stay inside an aligned group);
// min and max are exact in any order.
uint lanes_max(uint v) {
    [[unroll]] for (uint s = 1u; s < RAY_LANES; s <<= 1u) v = max(v, subgroupShuffleXor(v, s));
    return v;
}
float lanes_min(float v) {
    [[unroll]] for (uint s = 1u; s < RAY_LANES; s <<= 1u) v = min(v, subgroupShuffleXor(v, s));
    return v;
}
// Each pair adds the same two values (a + b == b + a), so every lane ends with the same sum.
vec3 lanes_sum(vec3 v) {
    [[unroll]] for (uint s = 1u; s < RAY_LANES; s <<= 1u) v += subgroupShuffleXor(v, s);
    return v;
}
float lanes_max(float v) {
    [[unroll]] for (uint s = 1u; s < RAY_LANES; s <<= 1u) v = max(v, subgroupShuffleXor(v, s));
    return v;
}
#else
#error "RAY_LANES is 1, 8, 16 or 32"
#endif
// The lanes below lane k (k <= RAY_LANES), as a ballot's bits.
uint lanes_below(uint k) { return k >= 32u ? 0xFFFFFFFFu : (1u << k) - 1u; }
// The first lane where c holds, RAY_LANES where none does.
uint lanes_first(bool c) {
    uint b = lanes_ballot(c);
    return b == 0u ? RAY_LANES : uint(findLSB(b));
}

// t after k more grid steps, summed one step at a time as the serial march sums them, so
// every lane's sample is bit for bit the one the serial march takes (k <= RAY_LANES;
// unrolled: llvmpipe's loop budget counts loop iterations).
float grid_ahead(float t, float step, uint k) {
    [[unroll]] for (uint j = 0u; j < RAY_LANES; ++j) {
        if (j < k) t += step;
    }
    return t;
}
#endif
