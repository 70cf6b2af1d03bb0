// The occupancy grid (occupancy.comp builds it, march.comp reads it): over the fluid's box
// (bounds +- R), cells at least R wide (at most OCC_DIM a side), a cell marked 1 where a
// metaball's sphere may reach it. Where no metaball is within R of a point every term is
// zero there, so the field is 0 < T: a ray outside the fluid cannot cross T at a sample in
// an unmarked cell, and its march passes over those samples with the same hits. The
// header (words 0..11) holds the grid as occupancy.comp computed it, so the march maps
// points to cells with the builder's numbers: lo.xyz, 1 / cell.xyz (float bits), dims.xyz.
#ifndef RENDER_METABALL_OCCUPANCY_GLSL
#define RENDER_METABALL_OCCUPANCY_GLSL
const uint OCC_DIM = 64u;
const uint OCC_CELLS = 16u;  // the first cell's word

struct OccGrid { vec3 lo; vec3 inv; uvec3 dims; };

// The grid of this frame's box (occupancy.comp; the march reads the header instead).
OccGrid occ_grid_of(vec3 lo, vec3 hi) {
    vec3 extent = max(hi - lo, vec3(1e-6));
    uvec3 dims = uvec3(clamp(floor(extent / radius()), vec3(1.0), vec3(float(OCC_DIM))));
    return OccGrid(lo, vec3(dims) / extent, dims);
}

OccGrid occ_header() {
    return OccGrid(
        uintBitsToFloat(uvec3(occupancy[0], occupancy[1], occupancy[2])),
        uintBitsToFloat(uvec3(occupancy[4], occupancy[5], occupancy[6])),
        uvec3(occupancy[8], occupancy[9], occupancy[10]));
}

// The cell holding x, NIL outside the grid (or before a grid was built: dims 0, or where
// a coordinate is not a number: both tests fail on NaN).
uint occ_cell(OccGrid g, vec3 x) {
    vec3 c = floor((x - g.lo) * g.inv);
    if (!(all(greaterThanEqual(c, vec3(0.0))) && all(lessThan(c, vec3(g.dims))))) return NIL;
    uvec3 u = uvec3(c);
    return (u.z * g.dims.y + u.y) * g.dims.x + u.x;
}
#endif
