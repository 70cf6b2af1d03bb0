// The surfaces beside the metaballs (src/sim/render/surface): screen-space fluid and marching
// cubes write one G-buffer that shade.comp lights with the metaballs' materials. Bindings:
// SurfaceIo in src/sim/render/surface/mod.rs (SF_B_* defines); Push mirrors SurfacePush there.
#ifndef SURFACE_COMMON_GLSL
#define SURFACE_COMMON_GLSL
#include "render/params.glsl"
layout(std430, binding = SF_B_PARAMS) readonly buffer Params { RenderParams P; };
layout(std430, binding = SF_B_CENTERS) readonly buffer Centers { vec4 centers[]; };  // xyz, w < 0: none
layout(std430, binding = SF_B_STATS) buffer Stats { RenderStats stats; };
layout(std430, binding = SF_B_PIXELS) writeonly buffer Pixels { uint pixels[]; };  // RGBA8
layout(std430, binding = SF_B_SKY) readonly buffer Sky { uint sky[]; };  // RGBA8
// Opaque layer (a character's mesh): W*H RGBA8 colours, then W*H depths (0..1, 1 = none).
layout(std430, binding = SF_B_OPAQUE) readonly buffer Opaque { uint opaque[]; };
layout(std430, binding = SF_B_SCENE_DEPTH) writeonly buffer SceneDepth { float scene_depth[]; };
// Nearest view depth per pixel as float bits (positive floats order as uints: atomicMin);
// NO_DEPTH where nothing was drawn.
layout(std430, binding = SF_B_ZBITS) buffer Zbits { uint zbits[]; };
// Thickness per pixel in 1/THICK_SCALE m (splats add chords; mesh faces add +-depth).
layout(std430, binding = SF_B_THICK) buffer Thick { int thick[]; };
// The G-buffer: per pixel (view depth, 0: none; world normal), then (thickness along the ray).
layout(std430, binding = SF_B_GBUF) buffer Gbuf { vec4 gbuf[]; };
// Screen-space smoothing: (depth, thickness) after the x pass, then after the y pass.
layout(std430, binding = SF_B_SMOOTHED) buffer Smoothed { vec2 smoothed[]; };
// Marching cubes: the density over the rest density at the grid's nodes, x fastest, in
// 1/GRID_SCALE (atomic adds).
layout(std430, binding = SF_B_GRID) buffer Grid { uint grid[]; };
// The case table from src/sim/isosurface/table.rs: 257 offsets into the triangles, 12 edges
// (corner a | corner b << 4), then triangles (edge e0 | e1 << 4 | e2 << 8).
layout(std430, binding = SF_B_CASES) readonly buffer Cases { uint cases[]; };
// Triangle soup: per vertex (position, 1), (unit normal out of the fluid, 0).
layout(std430, binding = SF_B_VERTS) buffer Verts { vec4 verts[]; };
// VkDrawIndirectCommand of the mesh: vertex count (atomic), 1, 0, 0; then the lowest and
// highest grid node any particle reached (atomicMin, atomicMax: x, y, z each).
layout(std430, binding = SF_B_ARGS) buffer Args { uint args[]; };
layout(push_constant) uniform Push {
    vec4 origin;  // grid origin xyz, w = cell
    uvec4 dims;   // grid nodes xyz, w = vertex capacity
    vec4 fluid;   // x: smoothing length h, y: particle volume m / rho0, z: poly6 constant, w: splat radius
    vec4 look;    // x: iso level, y: smoothing axis (0: x, 1: y), z: filter half-width cap (pixels)
} pc;
// GRID_SCALE and THICK_SCALE: the fixed points, from src/sim/render/surface/mod.rs.
#if !defined(GRID_SCALE) || !defined(THICK_SCALE)
#error "GRID_SCALE and THICK_SCALE come from src/sim/render/surface/mod.rs"
#endif
const uint NO_DEPTH = 0xFFFFFFFFu;

uint pixel_count() { return P.width * P.height; }

// Distance in front of the eye along the view axis.
float view_depth(vec3 x) {
    return -(P.view[0].z * x.x + P.view[1].z * x.y + P.view[2].z * x.z + P.view[3].z);
}

// The primary ray's unit direction through the centre of pixel q.
vec3 primary_dir(vec2 q) {
    vec2 ndc = (q + 0.5) / vec2(P.width, P.height) * 2.0 - 1.0;
    vec4 a = P.inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec4 b = P.inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(b.xyz / b.w - a.xyz / a.w);
}

// View depth per unit distance along direction d.
float depth_rate(vec3 d) {
    return -(P.view[0].z * d.x + P.view[1].z * d.y + P.view[2].z * d.z);
}
#endif
