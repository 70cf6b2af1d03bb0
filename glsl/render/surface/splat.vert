#version 450
// Screen-space fluid, depth splats: one quad per particle covering its sphere of the splat
// radius (render/sphere_quad.glsl).
invariant gl_Position;
#include "common.glsl"
#include "render/sphere_quad.glsl"
layout(location = 0) flat out uint v_id;

void main() {
    uint id = gl_InstanceIndex;
    v_id = id;
    gl_Position = sphere_quad(centers[id].xyz, pc.fluid.w, centers[id].w < 0.0, gl_VertexIndex);
}
