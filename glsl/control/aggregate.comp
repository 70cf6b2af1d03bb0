#version 450
// Per control-grid cell, the sums the deficit attraction and the damping read (one thread
// a cell over its sorted control particles): deficit-weighted position and deficit,
// position and count, velocity. Far cells then cost one read each instead of a loop over
// their particles (about 40 at the rest spacing in a cell of h_c).
#include "common.glsl"
void main() {
    uint k = global_id();
    uint cells = C.dims.x * C.dims.y * C.dims.z;
    if (k >= cells) return;
    uint s = cstart[k], e = s + ccount[k];
    vec4 def = vec4(0.0), at = vec4(0.0), v = vec4(0.0);
    for (uint j = s; j < e && j < C.live; ++j) {
        float d = max(1.0 - crho[j] / P.rest_density, 0.0);
        def += vec4(d * cpos[j].xyz, d);
        at += vec4(cpos[j].xyz, 1.0);
        v.xyz += control_velocity(j);
    }
    cagg[3 * k] = def;
    cagg[3 * k + 1] = at;
    cagg[3 * k + 2] = v;
}
