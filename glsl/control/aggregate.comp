#version 450
// Per control-grid cell, the sums the deficit attraction and the damping read (one thread
// a cell over the sorted control particles of its 2 x 2 x 2 fine cells): deficit-weighted position and deficit,
// position and count, velocity. Far cells then cost one read each instead of a loop over
// their particles (about 40 at the rest spacing in a cell of h_c).
#include "common.glsl"
void main() {
    uint k = global_id();
    uint cells = C.dims.x * C.dims.y * C.dims.z;
    if (k >= cells) return;
    ivec3 c0 = ivec3(k % C.dims.x, (k / C.dims.x) % C.dims.y, k / (C.dims.x * C.dims.y));
    vec4 def = vec4(0.0), at = vec4(0.0), v = vec4(0.0);
    // The cell's 2 x 2 x 2 fine cells (fewer at the grid's far faces).
    for (int n = 0; n < 8; ++n) {
        ivec3 c = 2 * c0 + ivec3(n & 1, (n >> 1) & 1, n >> 2);
        if (any(greaterThanEqual(c, ivec3(C.fine_dims.xyz)))) continue;
        uvec2 r = fine_range(c);
        for (uint j = r.x; j < r.y && j < C.live; ++j) {
            float d = max(1.0 - crho[j] / P.rest_density, 0.0);
            def += vec4(d * cpos[j].xyz, d);
            at += vec4(cpos[j].xyz, 1.0);
            v.xyz += control_velocity(j);
        }
    }
    cagg[3 * k] = def;
    cagg[3 * k + 1] = at;
    cagg[3 * k + 2] = v;
}
