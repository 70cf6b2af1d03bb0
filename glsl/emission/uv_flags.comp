#version 450
// The coverage mask as 0/1 per texel, for the scan that numbers the covered texels.
#include "common/index.glsl"
#include "uv.glsl"
void main() {
    uint i = global_id();
    if (i > pc.size.z) return;
    flags[i] = i < pc.size.z && pos[i].w > 0.5 ? 1u : 0u;
}
