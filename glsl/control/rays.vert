#version 450
// Rays placement, count and fill passes: the skinned triangles projected along +z onto
// the pixel grid (no depth test, no culling); each vertex carries its triangle's sign
// (+1 where the outward normal faces -z: a ray going +z enters there) and its world z.
#include "rays.glsl"
// The count and fill passes must rasterise the same fragments.
invariant gl_Position;
layout(location = 0) out float v_z;
layout(location = 1) flat out float v_sign;
void main() {
    uint t = gl_VertexIndex / 3u;
    vec3 a = verts[indices[3u * t]].xyz;
    vec3 b = verts[indices[3u * t + 1u]].xyz;
    vec3 c = verts[indices[3u * t + 2u]].xyz;
    vec3 p = verts[indices[gl_VertexIndex]].xyz;
    float nz = cross(b - a, c - a).z;
    v_sign = nz < 0.0 ? 1.0 : -1.0;
    v_z = p.z;
    vec2 ext = vec2(pc.dims.xy) * pc.lo.w;
    gl_Position = vec4((p.xy - pc.lo.xy) / ext * 2.0 - 1.0, 0.5, 1.0);
}
