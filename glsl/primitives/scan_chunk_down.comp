#version 450
// Scan level pass 2: each invocation scans its chunk serially from its offset (the
// exclusive scan of the chunk sums). Input and output may be the same buffer.
#include "common/index.glsl"
#include "scan_io.glsl"
void main() {
    uint c = global_id();
    if (c * CHUNK >= pc.n) return;
    run_scan(c * CHUNK, CHUNK, sums[pc.base + c]);
}
