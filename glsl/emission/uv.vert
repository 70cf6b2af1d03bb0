#version 450
// RenderToUV: each corner placed at its UV (scaled and offset into the atlas), carrying
// its skinned world position; no culling (UV islands may be mirrored).
#include "uv.glsl"
invariant gl_Position;
layout(location = 0) out vec3 v_world;
void main() {
    uint v = indices[gl_VertexIndex];
    vec2 uv = uvs[v] * pc.atlas.xy + pc.atlas.zw;
    v_world = verts[v].xyz;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.5, 1.0);
}
