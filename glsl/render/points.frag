#version 450
// Sphere impostor: discard outside the disc, shade by the view-facing normal.
layout(location = 0) in vec2 uv;
layout(location = 1) in vec4 col;
layout(location = 0) out vec4 out_color;
void main() {
    float d2 = dot(uv, uv);
    if (d2 > 1.0) discard;
    float nz = sqrt(1.0 - d2);
    out_color = vec4(col.rgb * (0.35 + 0.65 * nz), 1.0);
}
