#version 450
// A skinned mesh (src/sim/render/mesh.rs): vertices pulled from the skinning pass's output by
// the index buffer, three per triangle, with the corner's barycentric for the wireframe.
// Drawn in more than one pass against the same depth: the same inputs give bit-equal positions.
invariant gl_Position;
layout(std430, binding = MESH_B_POS) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = MESH_B_NRM) readonly buffer Nrm { vec4 nrm[]; };
layout(std430, binding = MESH_B_INDICES) readonly buffer Indices { uint indices[]; };
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;    // xyz camera position
    vec4 color;  // rgb, w = 1: wireframe
} pc;
layout(location = 0) out vec3 normal;
layout(location = 1) out vec3 world;
layout(location = 2) out vec3 bary;
void main() {
    uint v = indices[gl_VertexIndex];
    world = pos[v].xyz;
    normal = nrm[v].xyz;
    bary = vec3(0.0);
    bary[gl_VertexIndex % 3] = 1.0;
    gl_Position = pc.view_proj * vec4(world, 1.0);
}
