#version 450
// RenderToUV: the texel's surface point and layout triangle (where UV islands overlap,
// one of them).
#include "uv.glsl"
layout(location = 0) in vec3 v_world;
layout(location = 1) flat in uint v_tri;
void main() {
    uvec2 q = uvec2(gl_FragCoord.xy);
    pos[q.y * pc.size.x + q.x] = vec4(v_world, float(v_tri + 1u));
}
