#version 450
// Scan of up to WG * IPT elements in one workgroup (the top level): each invocation sums
// its IPT elements, a workgroup scan (subgroup or shared memory) gives its offset, then it
// scans them serially.
#include "common/index.glsl"
#include "workgroup.glsl"
#include "scan_io.glsl"
void main() {
    uint first = gl_LocalInvocationIndex * IPT;
    uint total;
    uint pre = wg_exclusive_scan(run_sum(first, IPT), total);
    run_scan(first, IPT, pre);
}
