#version 450
// Marching cubes, triangles: one invocation per cell classifies its 8 corners against the
// iso level, takes its case's triangles from the table and appends them to the soup (an
// atomic add on the draw's vertex count), each vertex on its grid edge where the density
// crosses the level, its normal from the density's gradient (central differences, one-sided
// at the boundary), as surface::march does. Triangles past the capacity are counted as
// overflow, never written: the caller grows the soup and redoes the frame.
#include "common/index.glsl"
#include "common.glsl"

ivec3 dims() { return ivec3(pc.dims.xyz); }
uint node(ivec3 q) { return uint((q.z * dims().y + q.y) * dims().x + q.x); }
float value(ivec3 q) { return float(grid[node(q)]) / GRID_SCALE; }
ivec3 corner(uint c) { return ivec3(c & 1u, (c >> 1) & 1u, (c >> 2) & 1u); }

vec3 gradient(ivec3 q) {
    vec3 g;
    for (int k = 0; k < 3; ++k) {
        ivec3 lo = q, hi = q;
        lo[k] = max(q[k] - 1, 0);
        hi[k] = min(q[k] + 1, dims()[k] - 1);
        g[k] = (value(hi) - value(lo)) / (float(max(hi[k] - lo[k], 1)) * pc.origin.w);
    }
    return g;
}

void main() {
    uint id = global_id();
    ivec3 cells = dims() - 1;
    if (id >= uint(cells.x * cells.y * cells.z)) return;
    ivec3 c = ivec3(id % uint(cells.x), id / uint(cells.x) % uint(cells.y), id / uint(cells.x * cells.y));
    // A cell with no node a particle reached has no density: below the level, empty.
    uvec3 lo = uvec3(args[4], args[5], args[6]), hi = uvec3(args[7], args[8], args[9]);
    if (any(lessThan(uvec3(c) + 1u, lo)) || any(greaterThan(uvec3(c), hi))) return;
    float iso = pc.look.x;
    float v[8];
    uint mask = 0u;
    for (uint k = 0u; k < 8u; ++k) {
        v[k] = value(c + corner(k));
        if (v[k] >= iso) mask |= 1u << k;
    }
    uint start = cases[mask], count = cases[mask + 1u] - start;
    if (count == 0u) return;
    atomicAdd(stats.triangles, count);
    uint base = atomicAdd(args[0], 3u * count);
    if (base + 3u * count > pc.dims.w) {
        atomicAdd(stats.overflow, count);
        return;
    }
    for (uint k = 0u; k < count; ++k) {
        uint tri = cases[257u + 12u + start + k];
        for (uint j = 0u; j < 3u; ++j) {
            uint edge = cases[257u + ((tri >> (4u * j)) & 15u)];
            uint a = edge & 15u, b = edge >> 4;
            ivec3 qa = c + corner(a), qb = c + corner(b);
            float s = clamp((iso - v[a]) / (v[b] - v[a]), 0.0, 1.0);
            vec3 p = pc.origin.xyz + mix(vec3(qa), vec3(qb), s) * pc.origin.w;
            vec3 n = -mix(gradient(qa), gradient(qb), s);
            float l = length(n);
            uint at = 2u * (base + 3u * k + j);
            verts[at] = vec4(p, 1.0);
            verts[at + 1u] = vec4(l > 1e-20 ? n / l : vec3(0.0), 0.0);
        }
    }
}
