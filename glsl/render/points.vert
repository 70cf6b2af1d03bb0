#version 450
// Particle view: one camera-facing quad per particle (6 vertices, no vertex buffer).
// Depth-tested against the mesh and overlays drawn in other passes: bit-equal positions.
invariant gl_Position;
layout(std430, binding = PTS_B_POS) readonly buffer Pos { vec4 pos[]; };  // xyz, w = radius or 0
layout(std430, binding = PTS_B_COLOR) readonly buffer Color { vec4 color[]; };  // rgba
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 right;  // camera right in world space, w = radius scale (the radius when pos.w = 0)
    vec4 up;     // camera up in world space
} pc;
layout(location = 0) out vec2 uv;
layout(location = 1) out vec4 col;
const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                               vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
void main() {
    vec4 p = pos[gl_InstanceIndex];
    vec2 c = corners[gl_VertexIndex];
    if (p.w < 0.0) {  // a dead slot (emission): degenerate, culled
        gl_Position = vec4(2.0, 2.0, 0.5, 1.0);
        return;
    }
    float r = (p.w > 0.0 ? p.w : 1.0) * pc.right.w;  // w: per-particle radius, or 0
    vec3 world = p.xyz + (c.x * pc.right.xyz + c.y * pc.up.xyz) * r;
    gl_Position = pc.view_proj * vec4(world, 1.0);
    uv = c;
    col = color[gl_InstanceIndex];
}
