#version 450
// One screen-aligned quad per metaball covering its sphere of radius R (sphere_quad.glsl).
// Every list pass draws these quads against the same depth: bit-equal positions.
invariant gl_Position;
#include "common.glsl"
#include "render/sphere_quad.glsl"
layout(location = 0) flat out uint v_id;

void main() {
    uint id = gl_InstanceIndex;
    v_id = id;
    gl_Position = sphere_quad(centers[id].xyz, radius(), centers[id].w < 0.0, gl_VertexIndex);
}
