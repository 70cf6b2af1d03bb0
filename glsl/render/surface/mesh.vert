#version 450
// Marching cubes, drawing the soup (indirect, its vertex count from cells.comp): world
// position and normal per vertex, and whether the triangle faces the eye (from its corners,
// so all three vertices agree). Both passes draw it against the same depth: bit-equal
// positions.
invariant gl_Position;
#include "common.glsl"
layout(location = 0) out vec3 world;
layout(location = 1) out vec3 normal;
layout(location = 2) flat out float facing;

void main() {
    uint i = gl_VertexIndex;
    if (i >= pc.dims.w) {  // past the capacity: the frame is redone
        gl_Position = vec4(2.0, 2.0, 0.5, 1.0);
        world = normal = vec3(0.0);
        facing = 0.0;
        return;
    }
    uint t = i - i % 3u;
    vec3 a = verts[2u * t].xyz, b = verts[2u * t + 2u].xyz, c = verts[2u * t + 4u].xyz;
    facing = dot(cross(b - a, c - a), P.eye.xyz - a) > 0.0 ? 1.0 : -1.0;
    world = verts[2u * i].xyz;
    normal = verts[2u * i + 1u].xyz;
    gl_Position = P.view_proj * vec4(world, 1.0);
}
