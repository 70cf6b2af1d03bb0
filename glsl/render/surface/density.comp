#version 450
// Marching cubes, density: each particle adds its poly6 share of the SPH density over the
// rest density, m W(r, h) / rho0, to the grid nodes within h (fixed point, atomic adds),
// as surface::density_grid does on the CPU; and the box of nodes reached.
#include "common/index.glsl"
#include "common.glsl"

void main() {
    uint i = global_id();
    if (i >= P.n || centers[i].w < 0.0) return;
    vec3 c = centers[i].xyz;
    float h = pc.fluid.x, cell = pc.origin.w, h2 = h * h;
    ivec3 dims = ivec3(pc.dims.xyz);
    vec3 g = (c - pc.origin.xyz) / cell;
    ivec3 lo = max(ivec3(ceil(g - h / cell)), ivec3(0));
    ivec3 hi = min(ivec3(floor(g + h / cell)), dims - 1);
    if (any(greaterThan(lo, hi))) return;
    // The nodes reached, so cells.comp skips the rest of the grid (all below the level).
    for (int k = 0; k < 3; ++k) {
        atomicMin(args[4 + k], uint(lo[k]));
        atomicMax(args[7 + k], uint(hi[k]));
    }
    float scale = pc.fluid.y * pc.fluid.z * GRID_SCALE;
    for (int z = lo.z; z <= hi.z; ++z) {
        for (int y = lo.y; y <= hi.y; ++y) {
            for (int x = lo.x; x <= hi.x; ++x) {
                vec3 e = pc.origin.xyz + vec3(x, y, z) * cell - c;
                float q = h2 - dot(e, e);
                if (q > 0.0) atomicAdd(grid[(z * dims.y + y) * dims.x + x], uint(scale * q * q * q + 0.5));
            }
        }
    }
}
