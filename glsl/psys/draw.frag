#version 450
// Points: round, opaque. Streaks: the colour, alpha-blended. Sprites: the texture's
// coverage times the particle's opacity, alpha-blended back to front.
#include "draw.glsl"
#if MODE != 0
layout(location = 0) in vec2 uv;
#endif
layout(location = 1) in vec4 col;
layout(location = 0) out vec4 out_color;
float texel(ivec2 t) {
    int n = int(pc.screen.w);
    t = clamp(t, ivec2(0), ivec2(n - 1));
    return sprite[t.y * n + t.x];
}
void main() {
#if MODE == 0
    vec2 uv = gl_PointCoord * 2.0 - 1.0;
    if (dot(uv, uv) > 1.0) discard;
    out_color = vec4(col.rgb, 1.0);
#elif MODE == 1
    out_color = vec4(col.rgb, col.a * mix(0.15, 1.0, uv.x));  // the tail fades
#elif MODE == 2
    float n = pc.screen.w;
    vec2 f = (uv * 0.5 + 0.5) * n - 0.5;
    ivec2 i = ivec2(floor(f));
    vec2 w = f - floor(f);
    float a = mix(mix(texel(i), texel(i + ivec2(1, 0)), w.x),
                  mix(texel(i + ivec2(0, 1)), texel(i + ivec2(1, 1)), w.x), w.y);
    out_color = vec4(col.rgb, col.a * a);
    if (out_color.a < 1.0 / 255.0) discard;
#else
#error "MODE is 0 (points), 1 (streaks) or 2 (sprites)"
#endif
}
