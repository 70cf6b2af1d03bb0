#version 450
// Rays placement, per pixel: sort its fragments by z (insertion sort: lists are short,
// a few crossings per pixel), then count the lattice steps inside (rays_walk.glsl).
#include "common/index.glsl"
#include "rays_walk.glsl"
void main() {
    uint p = global_id();
    if (p >= pc.pixels) return;
    uint s = range_start(p), e = min(offsets[p], pc.dims.w);
    for (uint i = s + 1u; i < e; ++i) {
        vec2 v = frags[i];
        uint j = i;
        while (j > s && frags[j - 1u].x > v.x) {
            frags[j] = frags[j - 1u];
            --j;
        }
        frags[j] = v;
    }
    uint n = 0u;
    float wind = 0.0;
    for (uint i = s; i < e; ++i) {
        vec2 f = frags[i];
        if (abs(wind) > 0.5 && i > s) n += uint(max(first_step(f.x) - first_step(frags[i - 1u].x), 0));
        wind += f.y;
    }
    emit[p] = n;
}
