#version 450
// One particle per VERTS vertices: MODE 0 points (one vertex, right.w pixels), 1 streaks (a
// line from a frame ago to now), 2 camera-facing sprites (a quad). Attributes over life (size, colour,
// opacity) are keyframe curves of age / life.
// Opaque and blended draws test one depth buffer: bit-equal positions.
invariant gl_Position;
#include "draw.glsl"
#include "closed.glsl"
#if MODE != 0
layout(location = 0) out vec2 uv;
#endif
layout(location = 1) out vec4 col;
const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                               vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
void cull() {
    gl_Position = vec4(2.0, 2.0, 0.5, 1.0);
#if MODE != 0
    uv = vec2(0.0);
#endif
    col = vec4(0.0);
}
void main() {
#if MODE == 0
    const uint VERTS = 1u;
#elif MODE == 1
    const uint VERTS = 2u;
#elif MODE == 2
    const uint VERTS = 6u;
#else
#error "MODE is 0 (points), 1 (streaks) or 2 (sprites)"
#endif
    uint inst = uint(gl_VertexIndex) / VERTS, corner = uint(gl_VertexIndex) % VERTS;
    uint slot = pc.identity == 1u ? inst : order[pc.offset + inst];
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
    float fs, fa;
    vec3 fc;
    CURVE1(sp.size_keys, sp.counts.z, u, fs);
    CURVE3(sp.color_keys, sp.counts.w, u, fc);
    CURVE1(sp.opacity_keys, sp.counts2.x, u, fa);
    float size = Q.w * fs;
    vec4 c = color[slot];
    c.rgb *= fc;
    c.a *= fa;
    col = c;
#if MODE == 0
    gl_Position = pc.view_proj * vec4(p, 1.0);
    gl_PointSize = pc.right.w;
#elif MODE == 1
    gl_Position = pc.view_proj * vec4(corner == 0u ? before : p, 1.0);
    uv = vec2(corner == 0u ? 0.0 : 1.0, 0.0);  // 0 at the tail
#elif MODE == 2
    vec2 k = corners[corner];
    vec3 world = p + (k.x * pc.right.xyz + k.y * pc.up.xyz) * 0.5 * size;
    gl_Position = pc.view_proj * vec4(world, 1.0);
    uv = k;
#else
#error "MODE is 0 (points), 1 (streaks) or 2 (sprites)"
#endif
}
