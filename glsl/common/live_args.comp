#version 450
// Indirect-dispatch group counts from the GPU-side live count (one invocation).
#include "live.glsl"
layout(local_size_x_id = 0) in;
layout(std430, binding = LIVE_B_COUNT) buffer Count { LiveCount live; };
void main() {
    uint l = max(live.local_size, 1u);
    live.groups[0] = (live.n + l - 1u) / l;
    live.groups[1] = 1u;
    live.groups[2] = 1u;
}
