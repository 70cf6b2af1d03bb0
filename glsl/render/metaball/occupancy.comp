#version 450
// The occupancy grid (occupancy.glsl), one invocation per metaball: every cell its sphere's
// box overlaps is marked, widened by 1% of R and of a cell so that rounding where the
// march maps a sample to a cell never leaves a reached cell unmarked. Every writer stores
// the same 1 (no atomics); the cells were cleared before.
#include "common/index.glsl"
#include "common.glsl"
#include "occupancy.glsl"

void main() {
    uint i = global_id();
    OccGrid g = occ_grid_of(bounds[0].xyz - vec3(radius()), bounds[1].xyz + vec3(radius()));
    if (i == 0u) {
        uvec3 lo = floatBitsToUint(g.lo), inv = floatBitsToUint(g.inv);
        occupancy[0] = lo.x; occupancy[1] = lo.y; occupancy[2] = lo.z;
        occupancy[4] = inv.x; occupancy[5] = inv.y; occupancy[6] = inv.z;
        occupancy[8] = g.dims.x; occupancy[9] = g.dims.y; occupancy[10] = g.dims.z;
    }
    if (i >= P.n) return;
    vec4 c = centers[i];
    if (c.w < 0.0) return;  // hidden: in no list and no sum
    float r = radius() * 1.01;
    ivec3 top = ivec3(g.dims) - 1;
    ivec3 a = clamp(ivec3(floor((c.xyz - r - g.lo) * g.inv - 0.01)), ivec3(0), top);
    ivec3 b = clamp(ivec3(floor((c.xyz + r - g.lo) * g.inv + 0.01)), ivec3(0), top);
    for (int z = a.z; z <= b.z; ++z)
        for (int y = a.y; y <= b.y; ++y)
            for (int x = a.x; x <= b.x; ++x)
                occupancy[OCC_CELLS + uint((z * int(g.dims.y) + y) * int(g.dims.x) + x)] = 1u;
}
