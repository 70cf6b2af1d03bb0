#version 450
// RenderToUV: the texel's surface point and layout triangle. Where UV islands overlap,
// the texel's owner (the lowest triangle covering it, claimed once at creation with
// pc.size.w = 1) writes, so every frame's point is the same triangle's.
#include "uv.glsl"
layout(location = 0) in vec3 v_world;
layout(location = 1) flat in uint v_tri;
void main() {
    uvec2 q = uvec2(gl_FragCoord.xy);
    uint t = q.y * pc.size.x + q.x;
    if (pc.size.w == 1u) {
        atomicMin(owner[t], v_tri);
    } else if (owner[t] == v_tri) {
        pos[t] = vec4(v_world, float(v_tri + 1u));
    }
}
