#version 450
// Per-tile lists, step 1 (src/sim/render/metaball/tiles.rs): each metaball's pixel rectangle
// (the billboard's, sphere_rect), its view depth and a depth key whose unsigned order is
// the depths' order; the depth sort then orders (ball_keys, ball_ids) front to back.
#include "common/index.glsl"
#include "common.glsl"
#include "render/sphere_quad.glsl"
void main() {
    uint i = global_id();
    if (i >= P.n) return;
    vec4 c = centers[i];
    uvec4 r = sphere_rect(c.xyz, radius(), c.w < 0.0);
    rects[i] = uvec2(r.x | r.y << 16, r.z | r.w << 16);
    float z = view_depth(c.xyz);
    depths[i] = z;
    uint b = floatBitsToUint(z);
    ball_keys[i] = (b & 0x80000000u) != 0u ? ~b : b | 0x80000000u;
    ball_ids[i] = i;
}
