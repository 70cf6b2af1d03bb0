#version 450
// Shaded: two-sided diffuse and a little specular under a fixed sun and sky light.
// Wireframe: triangle edges about a pixel wide, the rest discarded.
layout(push_constant) uniform Push {
    mat4 view_proj;
    vec4 eye;
    vec4 color;
} pc;
layout(location = 0) in vec3 normal;
layout(location = 1) in vec3 world;
layout(location = 2) in vec3 bary;
layout(location = 0) out vec4 out_color;
void main() {
    if (pc.color.w > 0.5) {
        vec3 w = fwidth(bary);
        vec3 edge = smoothstep(vec3(0.0), 0.8 * w, bary);
        float line = 1.0 - min(min(edge.x, edge.y), edge.z);
        if (line < 0.5) discard;
        out_color = vec4(pc.color.rgb, 1.0);
        return;
    }
    vec3 v = normalize(pc.eye.xyz - world);
    vec3 n = normalize(normal);
    if (dot(n, v) < 0.0) n = -n;  // open meshes show their inside too
    vec3 sun = normalize(vec3(0.4, 0.8, 0.3));
    float diffuse = max(dot(n, sun), 0.0);
    float sky = 0.5 + 0.5 * n.y;
    float spec = pow(max(dot(reflect(-sun, n), v), 0.0), 32.0);
    vec3 c = pc.color.rgb * (0.15 + 0.25 * sky + 0.7 * diffuse) + vec3(0.25 * spec);
    out_color = vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), 1.0);
}
