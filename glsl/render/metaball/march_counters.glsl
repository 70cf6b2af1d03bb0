// The march's counters (march.comp includes it after the march): rays, samples, terms and
// candidates, counted per invocation there, added here once per subgroup or workgroup.
#ifndef RENDER_METABALL_MARCH_COUNTERS_GLSL
#define RENDER_METABALL_MARCH_COUNTERS_GLSL
// The frame's counters (COUNTERS): rays, samples, terms and candidates, with the longest
// list and the off-screen samples, and the serial chains (the most evaluations one
// invocation made, the invocations that evaluated and their evaluations' sum) and the samples passed over
// in empty cells, added to the workgroup's counter slot (common.glsl: the
// frame's atomics spread over MARCH_SLOTS cache lines, summed by the host). WORKGROUP:
// each subgroup's sums meet in shared memory and one invocation per workgroup adds them;
// SUBGROUP: each subgroup adds its own; OFF: nothing counted (the increments above are
// then dead code), to measure what counting costs. (Before: every subgroup's atomics, and
// every pixel's longest list, met on stats' one cache line.) 64-bit totals stay exact:
// the low and high 16 bits of each count are summed apart (each sum fits 32 bits) and
// ADD64 adds them to the slot's (lo, hi) total at word W with its carries.
#define ADD64(W, LO, HI) { \
    uint lo_ = (LO), hi_ = (HI); \
    uint a_ = lo_ + (hi_ << 16), c_ = (hi_ >> 16) + (a_ < lo_ ? 1u : 0u); \
    uint o_ = atomicAdd(march_slots[W], a_); \
    c_ += o_ + a_ < o_ ? 1u : 0u; \
    if (c_ > 0u) atomicAdd(march_slots[(W) + 1u], c_); }

// Each subgroup's sums (the longest list and the longest serial chain their max).
// lo and hi: steps, evals, candidates, serial evaluations, skipped samples.
struct Sums { uint rays, longest, offscreen, serial_max, marching; uint lo[5], hi[5]; };
Sums subgroup_sums() {
    Sums s;
    uint counts[5] = uint[5](n_steps, n_evals, n_candidates, n_serial, n_skipped);
    s.rays = subgroupAdd(n_rays);
    s.longest = subgroupMax(longest);
    s.offscreen = subgroupAdd(offscreen_samples);
    s.serial_max = subgroupMax(n_serial);
    s.marching = subgroupAdd(n_serial > 0u ? 1u : 0u);
    [[unroll]] for (uint k = 0u; k < 5u; ++k) {
        s.lo[k] = subgroupAdd(counts[k] & 0xFFFFu);
        s.hi[k] = subgroupAdd(counts[k] >> 16);
    }
    return s;
}

// Sums added to the workgroup's slot, each only where it is not zero.
void add_sums(Sums s) {
    uint at = (group_id() % MARCH_SLOTS) * MARCH_SLOT_WORDS;
    if (s.rays > 0u) atomicAdd(march_slots[at], s.rays);
    if (s.longest > 0u) atomicMax(march_slots[at + 1u], s.longest);
    if (s.offscreen > 0u) atomicAdd(march_slots[at + 2u], s.offscreen);
    [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        if (s.lo[k] > 0u || s.hi[k] > 0u) ADD64(at + 3u + 2u * k, s.lo[k], s.hi[k])
    }
    if (s.serial_max > 0u) atomicMax(march_slots[at + 11u], s.serial_max);
    if (s.marching > 0u) atomicAdd(march_slots[at + 12u], s.marching);
    if (s.lo[4] > 0u || s.hi[4] > 0u) ADD64(at + 13u, s.lo[4], s.hi[4])
}

#if COUNTERS == COUNTERS_WORKGROUP
// rays, longest, off-screen, the lo then the hi of steps, evals, candidates and serial
// evaluations, the longest serial chain, the invocations that evaluated, the lo and hi of
// skipped samples.
shared uint c_sum[15];
void add_counters() {
    if (gl_LocalInvocationIndex == 0u) {
        [[unroll]] for (uint k = 0u; k < 15u; ++k) c_sum[k] = 0u;
    }
    barrier();
    Sums s = subgroup_sums();
    if (subgroupElect()) {
        atomicAdd(c_sum[0], s.rays);
        atomicMax(c_sum[1], s.longest);
        atomicAdd(c_sum[2], s.offscreen);
        [[unroll]] for (uint k = 0u; k < 4u; ++k) {
            atomicAdd(c_sum[3u + k], s.lo[k]);
            atomicAdd(c_sum[7u + k], s.hi[k]);
        }
        atomicMax(c_sum[11], s.serial_max);
        atomicAdd(c_sum[12], s.marching);
        atomicAdd(c_sum[13], s.lo[4]);
        atomicAdd(c_sum[14], s.hi[4]);
    }
    barrier();
    if (gl_LocalInvocationIndex != 0u) return;
    Sums w;
    w.rays = c_sum[0];
    w.longest = c_sum[1];
    w.offscreen = c_sum[2];
    [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        w.lo[k] = c_sum[3u + k];
        w.hi[k] = c_sum[7u + k];
    }
    w.serial_max = c_sum[11];
    w.marching = c_sum[12];
    w.lo[4] = c_sum[13];
    w.hi[4] = c_sum[14];
    add_sums(w);
}
#elif COUNTERS == COUNTERS_SUBGROUP
void add_counters() {
    Sums s = subgroup_sums();
    if (subgroupElect()) add_sums(s);
}
#elif COUNTERS == COUNTERS_OFF
void add_counters() {}
#else
#error "COUNTERS names no counter mode"
#endif
#endif
