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
    for (int dz = -n; dz <= n; ++dz) for (int dy = -n; dy <= n; ++dy) for (int dx = -n; dx <= n; ++dx) {
        ivec3 c = c0 + ivec3(dx, dy, dz);
        if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(C.dims.xyz)))) continue;
        uint id = (uint(c.z) * C.dims.y + uint(c.y)) * C.dims.x + uint(c.x);
        vec4 at = cagg[3 * id + 1];
        if (at.w == 0.0) continue;
        vec4 def = cagg[3 * id];
        if (def.w > 0.0) {
            vec3 d = def.xyz / def.w - xi;
            float r = length(d);
            if (r < R) {
                float w = (1.0 - r / R) * (1.0 - r / R) * def.w;
                if (r > 1e-6) pull += (w / r) * d;
                wdef += w;
            }
        }
        float r = length(at.xyz / at.w - xi);
        if (r < R) {
            float w = (1.0 - r / R) * (1.0 - r / R);
            vchar += w * cagg[3 * id + 2].xyz;
            wall += w * at.w;
        }
    }
    vec3 a = wdef > 0.0 ? C.attraction * pull / max(wdef, 1.0) : vec3(0.0);
    cfield[2 * k] = vec4(a, 0.0);
    cfield[2 * k + 1] = wall > 0.0 ? vec4(vchar / wall, 1.0) : vec4(0.0);
}
