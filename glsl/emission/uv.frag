#version 450
// RenderToUV: the texel's surface point (where UV islands overlap, one of them).
#include "uv.glsl"
layout(location = 0) in vec3 v_world;
void main() {
    uvec2 q = uvec2(gl_FragCoord.xy);
    pos[q.y * pc.size.x + q.x] = vec4(v_world, 1.0);
}
