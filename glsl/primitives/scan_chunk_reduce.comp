#version 450
// Scan level pass 1: each invocation sums one chunk of CHUNK contiguous elements.
// No barriers: the chunk sums form the next level of the scan.
#include "common/index.glsl"
#include "scan_io.glsl"
void main() {
    uint c = global_id();
    if (c * CHUNK >= pc.n) return;
    sums[pc.base + c] = run_sum(c * CHUNK, CHUNK);
}
