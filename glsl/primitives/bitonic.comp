#version 450
// Bitonic sort of key/value pairs, all comparators ascending: for each run size s a
// "flip" stage (x with its mirror in the run) and then half-cleaners at distance d.
// LOCAL_SORT: every s <= BLOCK inside a tile; GLOBAL: one stage (p = s, k = d, or k = 0
// for the flip) over the array; LOCAL_MERGE: the half-cleaners d < BLOCK of run size s.
#include "common/index.glsl"
#include "sort_common.glsl"

void tile_flip(uint s, uint valid) {
    uint h = s >> 1;
    for (uint c = gl_LocalInvocationIndex; c < BLOCK / 2u; c += gl_WorkGroupSize.x) {
        uint lo = (c / h) * s + (c % h);
        uint hi = lo ^ (s - 1u);
        if (hi < valid) tile_cmpswap(lo, hi);
    }
    barrier();
}

void tile_half_cleaners(uint d_start, uint valid) {
    for (uint d = d_start; d >= 1u; d >>= 1) {
        for (uint c = gl_LocalInvocationIndex; c < BLOCK / 2u; c += gl_WorkGroupSize.x) {
            uint lo = (c / d) * 2u * d + (c % d);
            if (lo + d < valid) tile_cmpswap(lo, lo + d);
        }
        barrier();
    }
}

void main() {
    if (pc.mode == MODE_GLOBAL) {
        uint c = global_id();
        uint lo, hi;
        if (pc.k == 0u) {  // flip stage of run size p
            uint h = pc.p >> 1;
            lo = (c / h) * pc.p + (c % h);
            hi = lo ^ (pc.p - 1u);
        } else {
            lo = (c / pc.k) * 2u * pc.k + (c % pc.k);
            hi = lo + pc.k;
        }
        if (hi < pc.n) global_cmpswap(lo, hi);
        return;
    }
    uint base = group_id() * BLOCK;
    tile_load(base);
    uint valid = min(BLOCK, pc.n - base);
    if (pc.mode == MODE_LOCAL_SORT) {
        for (uint s = 2; s <= BLOCK; s <<= 1) {
            tile_flip(s, valid);
            tile_half_cleaners(s >> 2, valid);
        }
    } else {
        tile_half_cleaners(BLOCK >> 1, valid);
    }
    tile_store(base);
}
