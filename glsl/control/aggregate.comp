#version 450
// Per control-grid cell, what the deficit attraction and the damping read (one thread a
// cell over its sorted control particles): deficit-weighted centre and deficit, centre
// and count, velocity sum. Far cells then cost one read each instead of a loop over
// their particles (about 40 at the rest spacing in a cell of h_c).
#include "common.glsl"
void main() {
    uint k = global_id();
    uint cells = C.dims.x * C.dims.y * C.dims.z;
    if (k >= cells) return;
    ivec3 c = ivec3(k % C.dims.x, (k / C.dims.x) % C.dims.y, k / (C.dims.x * C.dims.y));
    vec4 def = vec4(0.0), at = vec4(0.0), v = vec4(0.0);
    // A cell of h_c is 2 x 2 x 2 sorted cells of h_c / 2: four runs of two along x.
    for (int o = 0; o < 4; ++o) {
        ivec3 f = 2 * c + ivec3(0, o & 1, o >> 1);
        uvec2 r = fine_range(fine_id(f), fine_id(f) + 1u);
        for (uint j = r.x; j < r.y && j < C.live; ++j) {
            // A control particle's deficit is against the density the shape's own fill
            // gives there (its w, --control-deficit shape: about 0.8 at a flat surface, where
            // full fluid has only one side) or, w = 1 (rest) or 0 (rays), rest density.
            float full = cpos[j].w > 0.0 ? cpos[j].w : 1.0;
            float d = max(1.0 - crho[j] / (P.rest_density * full), 0.0);
            def += vec4(d * cpos[j].xyz, d);
            at += vec4(cpos[j].xyz, 1.0);
            v.xyz += cvw[j].xyz;
        }
    }
    // Centres, not sums: the field reads them for every cell within the reach.
    cagg[3 * k] = def.w > 0.0 ? vec4(def.xyz / def.w, def.w) : vec4(0.0);
    cagg[3 * k + 1] = at.w > 0.0 ? vec4(at.xyz / at.w, at.w) : vec4(0.0);
    cagg[3 * k + 2] = v;
}
