#version 450
// The deficit attraction and the character's velocity as a field on the control grid's
// cell centres (one thread a cell, over the per-cell sums of aggregate.comp within the
// reach): the force pass interpolates it trilinearly, so its cost per fluid particle is
// eight reads instead of a walk over the (2 reach / h_c + 1)^3 cells around it.
// cfield[2k] = (attraction acceleration, 0); cfield[2k + 1] = (sum w v / sum w n, mask):
// mask is 1 where some control particle lies within the reach (the damping's weight).
#include "common.glsl"
void main() {
    uint k = global_id();
    uint cells = C.dims.x * C.dims.y * C.dims.z;
    if (k >= cells) return;
    ivec3 c0 = ivec3(k % C.dims.x, (k / C.dims.x) % C.dims.y, k / (C.dims.x * C.dims.y));
    vec3 xi = C.grid.xyz + (vec3(c0) + 0.5) * C.grid.w;
    int n = int(C.reach_cells);
    float R = C.reach;
    vec3 pull = vec3(0.0), vchar = vec3(0.0);
    float wall = 0.0, wdef = 0.0;
    // Rows of cells along x are contiguous in the sorted set (cells numbered x fastest):
    // a row (clipped to the reach's chord) holding no control particle costs four reads,
    // and a cell with none in its whole neighbourhood (most of the domain) a few.
    ivec3 lo = max(c0 - n, ivec3(0)), hi = min(c0 + n, ivec3(C.dims.xyz) - 1);
    // (Sorted on cells of h_c / 2: in one slab of fine cells along z, the ids from a box's
    // first fine cell to its last span its fine cells and the rest of the rows between.)
    bool empty = true;
    for (int fz = 2 * lo.z; fz <= 2 * hi.z + 1 && empty; ++fz) {
        uvec2 r = fine_range(fine_id(ivec3(2 * lo.xy, fz)), fine_id(ivec3(2 * hi.xy + 1, fz)));
        empty = r.x == r.y;
    }
    if (empty) {
        cfield[2 * k] = vec4(0.0);
        cfield[2 * k + 1] = vec4(0.0);
        return;
    }
    for (int cz = lo.z; cz <= hi.z; ++cz) for (int cy = lo.y; cy <= hi.y; ++cy) {
        ivec2 span = row_span(xi, ivec2(cy, cz), C.grid.w, R);
        int x0 = max(span.x, lo.x), x1 = min(span.y, hi.x);
        if (x1 < x0) continue;
        uint row = (uint(cz) * C.dims.y + uint(cy)) * C.dims.x;
        uvec2 r0 = fine_range(fine_id(ivec3(2 * x0, 2 * cy, 2 * cz)), fine_id(ivec3(2 * x1 + 1, 2 * cy + 1, 2 * cz)));
        uvec2 r1 = fine_range(fine_id(ivec3(2 * x0, 2 * cy, 2 * cz + 1)), fine_id(ivec3(2 * x1 + 1, 2 * cy + 1, 2 * cz + 1)));
        if (r0.x == r0.y && r1.x == r1.y) continue;
        for (int cx = x0; cx <= x1; ++cx) {
            uint id = row + uint(cx);
            vec4 at = cagg[3 * id + 1];
            if (at.w == 0.0) continue;
            vec4 def = cagg[3 * id];
            if (def.w > 0.0) {
                vec3 d = def.xyz - xi;
                float r = length(d);
                if (r < R) {
                    float w = (1.0 - r / R) * (1.0 - r / R) * def.w;
                    if (r > 1e-6) pull += (w / r) * d;
                    wdef += w;
                }
            }
            float r = length(at.xyz - xi);
            if (r < R) {
                float w = (1.0 - r / R) * (1.0 - r / R);
                vchar += w * cagg[3 * id + 2].xyz;
                wall += w * at.w;
            }
        }
    }
    vec3 a = wdef > 0.0 ? C.attraction * pull / max(wdef, 1.0) : vec3(0.0);
    cfield[2 * k] = vec4(a, 0.0);
    cfield[2 * k + 1] = wall > 0.0 ? vec4(vchar / wall, 1.0) : vec4(0.0);
}
