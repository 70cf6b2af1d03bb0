#version 450
// Rays placement, per pixel: the control particles at the lattice steps inside, written
// from the pixel's scanned start (in pixel order, then z: deterministic).
#include "common/index.glsl"
#include "rays_walk.glsl"
void main() {
    uint p = global_id();
    if (p >= pc.pixels) return;
    uint s = range_start(p), e = min(offsets[p], pc.dims.w);
    uint o = emit[p];
    vec2 xy = pc.lo.xy + (vec2(p % pc.dims.x, p / pc.dims.x) + 0.5) * pc.lo.w;
    float wind = 0.0;
    for (uint i = s; i < e; ++i) {
        vec2 f = frags[i];
        if (abs(wind) > 0.5 && i > s) {
            int k1 = first_step(f.x);
            for (int k = first_step(frags[i - 1u].x); k < k1; ++k) {
                if (o < pc.capacity) outp[o] = vec4(xy, pc.lo.z + (float(k) + 0.5) * pc.lo.w, 0.0);
                ++o;
            }
        }
        wind += f.y;
    }
}
