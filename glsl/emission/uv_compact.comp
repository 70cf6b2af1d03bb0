#version 450
// Covered texels listed in texel order at their scanned index.
#include "common/index.glsl"
#include "uv.glsl"
void main() {
    uint i = global_id();
    if (i >= pc.size.z || pos[i].w <= 0.5) return;
    valid[flags[i]] = i;
}
