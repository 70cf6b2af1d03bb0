#version 450
// Indirect-dispatch group counts from the GPU-side live count (one invocation).
#include "live.glsl"
layout(local_size_x_id = 0) in;
layout(std430, binding = LIVE_B_COUNT) buffer Count { LiveCount live; };
// Past 65535 groups the dispatch is split over y, as ComputePipeline::dispatch_groups does
// (shaders linearise with global_id() and bounds-check).
void main() {
    uint l = max(live.local_size, 1u);
    uint total = (live.n + l - 1u) / l;
    uint gx = min(total, 65535u);
    live.groups[0] = gx;
    live.groups[1] = gx == 0u ? 1u : (total + gx - 1u) / gx;
    live.groups[2] = 1u;
}
