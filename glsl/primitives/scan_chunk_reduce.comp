#version 450
// Scan level pass 1: each invocation sums one chunk of CHUNK contiguous elements.
// No barriers: the chunk sums form the next level of the scan.
// TOP: the chunk sums are few enough for one workgroup (src/gpu/primitives/scan.rs,
// TOP_MOST), and the last workgroup to write its sums scans them in place (exclusive), so
// the next level needs no pass of its own; the arrival counter is the sums buffer's last
// element, 0 between scans.
#include "common/index.glsl"
#if TOP
#include "workgroup.glsl"
#endif
#include "scan_io.glsl"
#if TOP
shared bool s_last;
void main() {
    uint c = global_id();
    if (c * CHUNK < pc.n) sums[c] = run_sum(c * CHUNK, CHUNK);
    memoryBarrierBuffer();
    barrier();
    uint chunks = (pc.n + CHUNK - 1u) / CHUNK;
    uint groups = (chunks + gl_WorkGroupSize.x - 1u) / gl_WorkGroupSize.x;
    uint counter = uint(sums.length()) - 1u;
    if (gl_LocalInvocationIndex == 0u) s_last = atomicAdd(sums[counter], 1u) == groups - 1u;
    barrier();
    if (!s_last) return;
    memoryBarrierBuffer();
    // Each invocation scans a run of `per` sums (at most 64: TOP_MOST).
    uint per = (chunks + gl_WorkGroupSize.x - 1u) / gl_WorkGroupSize.x;
    uint first = gl_LocalInvocationIndex * per;
    uint s = 0u;
    for (uint k = 0u; k < per; ++k) s += first + k < chunks ? sums[first + k] : 0u;
    uint total;
    uint pre = wg_exclusive_scan(s, total);
    for (uint k = 0u; k < per; ++k) {
        if (first + k < chunks) {
            uint x = sums[first + k];
            sums[first + k] = pre;
            pre += x;
        }
    }
    if (gl_LocalInvocationIndex == 0u) sums[counter] = 0u;
}
#else
void main() {
    uint c = global_id();
    if (c * CHUNK >= pc.n) return;
    sums[pc.base + c] = run_sum(c * CHUNK, CHUNK);
}
#endif
