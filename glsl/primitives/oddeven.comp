#version 450
// Batcher's odd-even merge sort of key/value pairs. LOCAL_SORT sorts each tile of BLOCK
// elements in shared memory (all merges with 2p <= BLOCK); GLOBAL runs one (p, k)
// comparator stage over the array (its pairs straddle tiles, so no local merge here).
#include "common/index.glsl"
#include "sort_common.glsl"

// x is the lower end of a (p, k) comparator: the partner is x + k in the same 2p run.
bool is_lower(uint x, uint p, uint k) {
    uint j = k % p;
    if (x < j) return false;
    return ((x - j) & k) == 0u && (x / (2u * p)) == ((x + k) / (2u * p));
}

void main() {
    if (pc.mode == MODE_LOCAL_SORT) {
        uint base = group_id() * BLOCK;
        tile_load(base);
        uint valid = min(BLOCK, pc.n - base);
        for (uint p = 1; p < BLOCK; p <<= 1) {
            for (uint k = p; k >= 1u; k >>= 1) {
                for (uint x = gl_LocalInvocationIndex; x < BLOCK; x += gl_WorkGroupSize.x) {
                    if (is_lower(x, p, k) && x + k < valid) tile_cmpswap(x, x + k);
                }
                barrier();
            }
        }
        tile_store(base);
    } else {
        uint x = global_id();
        if (x < pc.n && is_lower(x, pc.p, pc.k) && x + pc.k < pc.n) global_cmpswap(x, x + pc.k);
    }
}
