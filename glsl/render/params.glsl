// The renderer's parameters and counters, shared by the metaball passes
// (render/metaball/common.glsl) and the other surfaces (render/surface/common.glsl).
// RenderParams and RenderStats mirror src/sim/render/metaball/settings.rs and stats.rs (field
// offsets tested).
#ifndef RENDER_PARAMS_GLSL
#define RENDER_PARAMS_GLSL
struct RenderParams {
    mat4 view_proj;
    mat4 inv_view_proj;
    mat4 view;
    vec4 proj;      // x: P00, y: P11, z: near plane distance
    vec4 eye;       // xyz camera position, w = metaball radius R
    vec4 sun;       // xyz unit direction towards the sun, w = march step
    vec4 absorb;    // rgb absorption per unit length (tinted), w = index of refraction
    vec4 f0;        // rgb Fresnel reflectance at normal incidence (metals)
    vec4 base;      // rgb Phong colour, w = threshold T
    vec4 tank_min;  // xyz container min, w = 1: draw it
    vec4 tank_max;  // xyz container max
    uint width;
    uint height;
    uint n;
    uint refine;
    uint depth;
    uint max_steps;
    uint list_capacity;  // S-buffer list or A-buffer pool entries
    uint offscreen_end;  // secondary samples off screen: 1 end the path, 0 use all metaballs
    uint sky_w;
    uint sky_h;
    uint debug;
    uint opaque;  // 1: the opaque layer is drawn (march.comp)
    // Per-tile lists (render/metaball/tiles.glsl): tile size in pixels, tiles per row, bits
    // of a pair key's depth rank (key = tile << rank_bits | rank), the pairs' capacity.
    uint tile;
    uint tiles_x;
    uint rank_bits;
    uint pair_capacity;
    uint occupancy;  // 1: secondary rays pass over the occupancy grid's empty cells
    uint pad0;
    uint pad1;
    uint pad2;
};
const uint NIL = 0xFFFFFFFFu;
struct RenderStats {
    uint abuffer_nodes;      // A-buffer node counter
    uint longest;            // longest list met by a primary ray
    uint overflow;           // list entries that did not fit
    uint offscreen_samples;  // secondary samples off screen
    uint sbuffer_fragments;  // S-buffer total (copied from the scan)
    uint budget_pixels;      // pixels whose loops were cut short
    uint triangles;          // marching cubes: triangles made (surface/cells.comp)
    uint rays;               // rays marched, primary and secondary
    // The march's per-ray counters, 64-bit totals as (lo, hi) (march.comp's add64).
    uvec2 steps;       // samples taken, refinement included
    uvec2 evals;       // metaball terms summed (field and gradient)
    uvec2 candidates;  // metaballs the primary rays' lists offer (none: every one)
    uint pairs;        // per-tile lists: (tile, metaball) pairs of the frame
    uint pad;
};
#endif
