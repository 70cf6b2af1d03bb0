// Metaball rendering (seed 000, section 4): parameters, bindings, density functions and
// the per-pixel metaball lists. Bindings: MetaballIo in src/sim/render/metaball/renderer.rs
// (MB_B_* defines); RenderParams and RenderStats mirror src/sim/render/metaball/settings.rs
// and stats.rs (field offsets tested). Defines from Rust: LIST (LIST_NONE | LIST_ABUFFER |
// LIST_SBUFFER | LIST_TILES), SORTED (1: S-buffer ranges sorted by depth), DENSITY (DENSITY_BLINN |
// _WYVILL | _NISHIMURA | _MURAKAMI | _WENDLAND), MATERIAL (MATERIAL_PHONG | _GLASS | _TINTED | _METAL).
#ifndef METABALL_COMMON_GLSL
#define METABALL_COMMON_GLSL

#include "render/params.glsl"
// S-buffer: one array of W*H + 1: counts, scanned in place into starts, then advanced by
// the fill to each pixel's end, so pixel p's range is [p == 0 ? 0 : offsets[p-1], offsets[p]).
layout(std430, binding = MB_B_PARAMS) readonly buffer Params { RenderParams P; };
layout(std430, binding = MB_B_CENTERS) readonly buffer Centers { vec4 centers[]; };  // xyz
layout(std430, binding = MB_B_BOUNDS) readonly buffer Bounds { vec4 bounds[]; };  // min, max
layout(std430, binding = MB_B_OFFSETS) buffer Offsets { uint offsets[]; };  // S offsets
layout(std430, binding = MB_B_LIST) buffer List { uint list[]; };  // S ranges
layout(std430, binding = MB_B_HEADS) buffer Heads { uint heads[]; };  // A heads
layout(std430, binding = MB_B_NODES) buffer Nodes { uvec2 nodes[]; };  // A (id, next)
// After the stats, the march's counter slots (march.comp's add_counters): MARCH_SLOTS
// of MARCH_SLOT_WORDS words, a workgroup adding to slot group % MARCH_SLOTS, so the
// frame's counter atomics spread over as many cache lines; the host sums them.
layout(std430, binding = MB_B_STATS) buffer Stats { RenderStats stats; uint march_slots[]; };
const uint MARCH_SLOTS = 64u, MARCH_SLOT_WORDS = 32u;
layout(std430, binding = MB_B_PIXELS) writeonly buffer Pixels { uint pixels[]; };  // RGBA8
layout(std430, binding = MB_B_DEBUG) writeonly buffer Debug { vec4 debug_out[]; };  // t, normal
layout(std430, binding = MB_B_SKY) readonly buffer Sky { uint sky[]; };  // RGBA8
layout(std430, binding = MB_B_DEPTHS) buffer Depths { float depths[]; };  // view depths
// Opaque layer (a character's mesh): W*H RGBA8 colours, then W*H depths (0..1, 1 = none).
layout(std430, binding = MB_B_OPAQUE) readonly buffer Opaque { uint opaque[]; };
// With the opaque layer: the NDC depth of the first surface each primary ray meets (march.comp).
layout(std430, binding = MB_B_SCENE_DEPTH) writeonly buffer SceneDepth { float scene_depth[]; };
// Per-tile lists (src/sim/render/metaball/tiles.rs): each metaball's pixel rectangle (x0 | y0
// << 16, x1 | y1 << 16), its depth key and index sorted front to back, each depth rank's
// first pair (W scanned), the (tile, metaball) pairs by key tile << rank_bits | rank, then
// sorted, each sorted pair's metaball (xyz, view depth), each tile's pair range [x, y).
layout(std430, binding = MB_B_RECTS) buffer Rects { uvec2 rects[]; };
layout(std430, binding = MB_B_BALL_KEYS) buffer BallKeys { uint ball_keys[]; };
layout(std430, binding = MB_B_BALL_IDS) buffer BallIds { uint ball_ids[]; };
layout(std430, binding = MB_B_PAIR_COUNTS) buffer PairCounts { uint pair_counts[]; };
layout(std430, binding = MB_B_PAIR_KEYS) buffer PairKeys { uint pair_keys[]; };
layout(std430, binding = MB_B_PAIR_IDS) buffer PairIds { uint pair_ids[]; };
layout(std430, binding = MB_B_TILE_BALLS) buffer TileBalls { vec4 tile_balls[]; };
layout(std430, binding = MB_B_TILE_RANGES) buffer TileRanges { uvec2 tile_ranges[]; };
// The occupancy grid (occupancy.glsl): a header, then one word per cell (1: reached).
layout(std430, binding = MB_B_OCCUPANCY) buffer Occupancy { uint occupancy[]; };

uint range_start(uint p) { return p == 0u ? 0u : offsets[p - 1u]; }

// Distance in front of the eye along the view axis (1-Lipschitz in x).
float view_depth(vec3 x) {
    return -(P.view[0].z * x.x + P.view[1].z * x.y + P.view[2].z * x.z + P.view[3].z);
}

float radius() { return P.eye.w; }
float threshold() { return P.base.w; }

// D(r) from r^2, normalised to D(0) = 1, zero from R on (src/sim/render/metaball/density.rs).
const float BLINN_A = 4.0;
float density2(float r2) {
    float R = radius();
#if DENSITY == DENSITY_WYVILL
    // Branch-free, one multiply by the hoisted 1 / R^2: (1 - q^2)^2 (1 - 4/9 q^2) is
    // Wyvill's polynomial factored, and its first factor is 0 from R on. (1 / R^2 read
    // from the parameters per term instead marched glass 1.3x slower on lavapipe: its
    // LLVM does not hoist that load out of the sums.)
    float q2 = r2 * (1.0 / (R * R));
    float a = max(1.0 - q2, 0.0);
    return a * a * (1.0 - 4.0 / 9.0 * q2);
#else
    float q2 = r2 / (R * R);
    if (q2 >= 1.0) return 0.0;
#if DENSITY == DENSITY_BLINN
    float fl = exp(-BLINN_A);
    return (exp(-BLINN_A * q2) - fl) / (1.0 - fl);
#elif DENSITY == DENSITY_NISHIMURA
    float q = sqrt(q2);
    return q <= 1.0 / 3.0 ? 1.0 - 3.0 * q2 : 1.5 * (1.0 - q) * (1.0 - q);
#elif DENSITY == DENSITY_MURAKAMI
    return (1.0 - q2) * (1.0 - q2);
#elif DENSITY == DENSITY_WENDLAND
    float q = sqrt(q2), u = 1.0 - q;
    return u * u * u * u * (4.0 * q + 1.0);
#else
#error "DENSITY names no density function"
#endif
#endif
}

// (dD/dr) / r = (dD/dq) / (q R^2), so grad D(|x - c|) = (x - c) * this; from r^2.
float density_grad_over_r(float r2) {
    float R = radius();
    float q2 = r2 / (R * R);
    if (q2 >= 1.0) return 0.0;
    float inv = 1.0 / (R * R);
#if DENSITY == DENSITY_BLINN
    float fl = exp(-BLINN_A);
    return -2.0 * BLINN_A * exp(-BLINN_A * q2) / (1.0 - fl) * inv;
#elif DENSITY == DENSITY_WYVILL
    return (-24.0 / 9.0 * q2 * q2 + 68.0 / 9.0 * q2 - 44.0 / 9.0) * inv;
#elif DENSITY == DENSITY_NISHIMURA
    float q = sqrt(q2);
    if (q <= 1.0 / 3.0) return -6.0 * inv;
    return q > 1e-12 ? -3.0 * (1.0 - q) / q * inv : 0.0;
#elif DENSITY == DENSITY_MURAKAMI
    return -4.0 * (1.0 - q2) * inv;
#elif DENSITY == DENSITY_WENDLAND
    float u = 1.0 - sqrt(q2);
    return -20.0 * u * u * u * inv;
#else
#error "DENSITY names no density function"
#endif
}

uint pixel_index(uvec2 p) { return p.y * P.width + p.x; }

// The tile holding pixel (x, y), and the one holding pixel index p.
uint tile_of(uvec2 pix) { return (pix.y / P.tile) * P.tiles_x + pix.x / P.tile; }
uint tile_of_pixel(uint p) { return tile_of(uvec2(p % P.width, p / P.width)); }

// Whether pixel (x, y) lies in a packed rectangle.
bool rect_holds(uvec2 r, uvec2 pix) {
    return pix.x >= (r.x & 0xFFFFu) && pix.y >= (r.x >> 16) && pix.x < (r.y & 0xFFFFu)
        && pix.y < (r.y >> 16);
}
#endif
