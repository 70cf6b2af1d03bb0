#version 450
// RenderToUV: each corner placed at its UV (scaled and offset into the atlas), carrying
// its skinned world position; no culling (UV islands may be mirrored). Corners are not
// shared: corner c (gl_VertexIndex, counted from the part's first) of layout triangle
// c / 3 indexes uvs and src.
#include "uv.glsl"
invariant gl_Position;
layout(location = 0) out vec3 v_world;
layout(location = 1) flat out uint v_tri;
void main() {
    uint c = gl_VertexIndex;
    vec2 uv = uvs[c] * pc.atlas.xy + pc.atlas.zw;
    v_world = verts[src[c]].xyz;
    v_tri = c / 3u;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.5, 1.0);
}
