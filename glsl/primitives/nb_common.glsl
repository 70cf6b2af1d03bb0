// Push constants and neighbour bindings of the neighbour-search passes.
#ifndef PRIMITIVES_NB_COMMON_GLSL
#define PRIMITIVES_NB_COMMON_GLSL
layout(push_constant) uniform Push {
    vec4 origin_cell;  // xyz grid origin, w cell size
    uvec4 dims;        // xyz grid cells, w hash table size
    float radius;
    uint n;
    uint max_neighbors;
    uint pad;
} pc;
#define NB_ORIGIN (pc.origin_cell.xyz)
#define NB_CELL (pc.origin_cell.w)
#define NB_DIMS (pc.dims.xyz)
#define NB_TABLE (pc.dims.w)
#define NB_N (pc.n)
#endif
