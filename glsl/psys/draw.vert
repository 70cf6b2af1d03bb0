#version 450
// One particle per instance: MODE 0 points (square of right.w pixels), 1 streaks (a line
// from a frame ago to now), 2 camera-facing sprites. Attributes over life (size, colour,
// opacity) are keyframe curves of age / life.
#include "draw.glsl"
#include "closed.glsl"
layout(location = 0) out vec2 uv;
layout(location = 1) out vec4 col;
const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                               vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
void cull() { gl_Position = vec4(2.0, 2.0, 0.5, 1.0); uv = vec2(0.0); col = vec4(0.0); }
void main() {
    uint slot = pc.identity == 1u ? gl_InstanceIndex : order[pc.offset + gl_InstanceIndex];
    if (slot == NO_SLOT) { cull(); return; }
    vec4 P = pos[slot], V = vel[slot], Q = prev[slot];
    vec3 p, before;
    float age;
    if (sp.counts2.y == I_CLOSED) {
        age = pc.up.w - P.w;
        if (P.w < 0.0 || age < 0.0 || age >= V.w) { cull(); return; }
        p = closed_pos(P.xyz, V.xyz, sp.gravity.xyz, age);
        before = closed_pos(P.xyz, V.xyz, sp.gravity.xyz, max(age - pc.screen.z, 0.0));
    } else {
        age = P.w;
        if (age < 0.0) { cull(); return; }
        p = P.xyz;
        before = Q.xyz;
    }
    float u = clamp(age / max(V.w, 1e-6), 0.0, 1.0);
    float size = Q.w * curve1(sp.size_keys, sp.counts.z, u);
    vec4 c = color[slot];
    c.rgb *= curve3(sp.color_keys, sp.counts.w, u);
    c.a *= curve1(sp.opacity_keys, sp.counts2.x, u);
    col = c;
#if MODE == 0
    vec2 k = corners[gl_VertexIndex];
    vec4 clip = pc.view_proj * vec4(p, 1.0);
    clip.xy += k * pc.right.w * 0.5 * pc.screen.xy * clip.w;
    gl_Position = clip;
    uv = k;
#elif MODE == 1
    gl_Position = pc.view_proj * vec4(gl_VertexIndex == 0 ? before : p, 1.0);
    uv = vec2(gl_VertexIndex == 0 ? 0.0 : 1.0, 0.0);  // 0 at the tail
#else
    vec2 k = corners[gl_VertexIndex];
    vec3 world = p + (k.x * pc.right.xyz + k.y * pc.up.xyz) * 0.5 * size;
    gl_Position = pc.view_proj * vec4(world, 1.0);
    uv = k;
#endif
}
