// Neighbour iteration shared by the query pass and the SPH passes.
// Before including, define:
//   NB_STRATEGY  0 grid | 1 hash | 2 morton         NB_CELL_COUNTS  1: nb_end holds counts
//   NB_B_KEYS, NB_B_START, NB_B_END, NB_B_BOX       binding numbers
//   NB_ORIGIN (vec3), NB_CELL (float), NB_DIMS (uvec3), NB_TABLE (uint), NB_N (uint)
// Then   NB_BEGIN(p, r, j) { ...candidate j (sorted index)... } NB_END
// visits every particle within r of p (r <= NB_CELL for grid and hash), and possibly more.
// NB_CELL_ONLY: only the cell functions (no buffers, no iteration).
#ifndef PRIMITIVES_NEIGHBORS_GLSL
#define PRIMITIVES_NEIGHBORS_GLSL
#extension GL_EXT_control_flow_attributes : require
// NB_GRID, NB_HASH, NB_MORTON, NB_STRATEGY and NB_CELL_COUNTS come from
// NeighborSearch::defines_for in src/gpu/primitives/neighbors.rs.
#include "morton.glsl"

ivec3 nb_cell_of(vec3 p) { return ivec3(floor((p - NB_ORIGIN) / NB_CELL)); }

// Grid cells are clamped, so particles outside the grid land in border cells; clamping
// never separates two points closer than one cell by more than one cell.
ivec3 nb_grid_cell(vec3 p) { return clamp(nb_cell_of(p), ivec3(0), ivec3(NB_DIMS) - 1); }
uint nb_grid_id(ivec3 c) { return (uint(c.z) * NB_DIMS.y + uint(c.y)) * NB_DIMS.x + uint(c.x); }
uint nb_hash(ivec3 c) {  // Teschner et al. 2003, table size a power of two
    return ((uint(c.x) * 73856093u) ^ (uint(c.y) * 19349663u) ^ (uint(c.z) * 83492791u)) & (NB_TABLE - 1u);
}

#ifndef NB_CELL_ONLY
layout(std430, binding = NB_B_KEYS) readonly buffer NbKeys { uint nb_keys[]; };    // sorted keys
layout(std430, binding = NB_B_START) readonly buffer NbStart { uint nb_start[]; }; // cell starts
layout(std430, binding = NB_B_END) readonly buffer NbEnd { uint nb_end[]; };       // ends or counts
layout(std430, binding = NB_B_BOX) readonly buffer NbBox { vec4 nb_box[]; };       // morton box

uint nb_lower_bound(uint key) {  // first sorted slot with nb_keys[slot] >= key
    uint lo = 0u, hi = NB_N;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1;
        if (nb_keys[mid] < key) lo = mid + 1u; else hi = mid;
    }
    return lo;
}
#if NB_CELL_COUNTS
#define NB_CELL_END(id, s) ((s) + nb_end[id])
#else
#define NB_CELL_END(id, s) (nb_end[id])
#endif

#if NB_STRATEGY == NB_GRID && NB_CELL_COUNTS
// Cell starts are a scan of the counts (empty cells included) and cells are numbered x
// fastest, so each of the 9 rows of three cells along x is one contiguous range.
#define NB_BEGIN(P, R, J) { ivec3 nb_c0 = nb_grid_cell(P); \
    int nb_x0 = max(nb_c0.x - 1, 0), nb_x1 = min(nb_c0.x + 1, int(NB_DIMS.x) - 1); \
    for (int nb_dz = -1; nb_dz <= 1; ++nb_dz) for (int nb_dy = -1; nb_dy <= 1; ++nb_dy) { \
        ivec2 nb_yz = nb_c0.yz + ivec2(nb_dy, nb_dz); \
        if (any(lessThan(nb_yz, ivec2(0))) || any(greaterThanEqual(nb_yz, ivec2(NB_DIMS.yz)))) continue; \
        uint nb_a = nb_grid_id(ivec3(nb_x0, nb_yz)), nb_b = nb_grid_id(ivec3(nb_x1, nb_yz)); \
        uint nb_s = nb_start[nb_a]; uint nb_e = nb_start[nb_b] + nb_end[nb_b]; \
        for (uint J = nb_s; J < nb_e; ++J) {
#define NB_END }}}
#elif NB_STRATEGY == NB_GRID
#define NB_BEGIN(P, R, J) { ivec3 nb_c0 = nb_grid_cell(P); \
    for (int nb_dz = -1; nb_dz <= 1; ++nb_dz) for (int nb_dy = -1; nb_dy <= 1; ++nb_dy) \
    for (int nb_dx = -1; nb_dx <= 1; ++nb_dx) { \
        ivec3 nb_c = nb_c0 + ivec3(nb_dx, nb_dy, nb_dz); \
        if (any(lessThan(nb_c, ivec3(0))) || any(greaterThanEqual(nb_c, ivec3(NB_DIMS)))) continue; \
        uint nb_id = nb_grid_id(nb_c); uint nb_s = nb_start[nb_id]; uint nb_e = NB_CELL_END(nb_id, nb_s); \
        for (uint J = nb_s; J < nb_e; ++J) {
#define NB_END }}}
#elif NB_STRATEGY == NB_HASH
// Two of the 27 cells may share a bucket: each bucket is visited once.
#define NB_BEGIN(P, R, J) { ivec3 nb_c0 = nb_cell_of(P); uint nb_seen[27]; uint nb_nseen = 0u; \
    for (int nb_dz = -1; nb_dz <= 1; ++nb_dz) for (int nb_dy = -1; nb_dy <= 1; ++nb_dy) \
    for (int nb_dx = -1; nb_dx <= 1; ++nb_dx) { \
        uint nb_h = nb_hash(nb_c0 + ivec3(nb_dx, nb_dy, nb_dz)); bool nb_dup = false; \
        for (uint nb_q = 0u; nb_q < nb_nseen; ++nb_q) nb_dup = nb_dup || nb_seen[nb_q] == nb_h; \
        if (nb_dup) continue; \
        nb_seen[nb_nseen++] = nb_h; \
        uint nb_s = nb_start[nb_h]; uint nb_e = NB_CELL_END(nb_h, nb_s); \
        for (uint J = nb_s; J < nb_e; ++J) {
#define NB_END }}}
#elif NB_STRATEGY == NB_MORTON
// Seed 000: the query box's corner codes bound a contiguous range of the sorted array.
// NB_UNROLL candidates per iteration of the outer loop, the inner loop unrolled away:
// llvmpipe stops an invocation's loops after about 65535 iterations in total, and a range
// that straddles the top octants spans most of the array (16 per iteration: about 1M
// candidates; 32 costs 40% more time at 64K on lavapipe).
#ifndef NB_UNROLL
#define NB_UNROLL 16u
#endif
#define NB_BEGIN(P, R, J) { \
    uint nb_lo = morton_code(morton_cell((P) - vec3(R), nb_box[0].xyz, nb_box[1].xyz)); \
    uint nb_hi = morton_code(morton_cell((P) + vec3(R), nb_box[0].xyz, nb_box[1].xyz)); \
    bool nb_more = true; \
    for (uint nb_b = nb_lower_bound(nb_lo); nb_more; nb_b += NB_UNROLL) { \
    [[unroll]] for (uint nb_u = 0u; nb_u < NB_UNROLL; ++nb_u) { \
        uint J = nb_b + nb_u; \
        if (!nb_more || J >= NB_N || nb_keys[J] > nb_hi) { nb_more = false; continue; }
#define NB_END }}}
#else
#error "NB_STRATEGY names no neighbour search"
#endif
#endif // NB_CELL_ONLY
#endif
