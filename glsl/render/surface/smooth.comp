#version 450
// Screen-space fluid, smoothing: a separable bilateral filter of the splatted depth (the
// x pass, then the y pass): Gaussian in pixels with twice the splat's projected radius as
// sigma (the spheres' bumps are a spacing apart; the reach at most the cap), times a
// Gaussian in depth difference with twice the splat radius as sigma,
// so the spheres' bumps flatten without blurring across silhouettes. The thickness takes
// the same weights. Pixels without fluid stay without.
#include "common/index.glsl"
#include "common.glsl"

// (depth, thickness) at pixel q before this pass; depth 0: none.
vec2 input_at(ivec2 q) {
    uint i = uint(q.y) * P.width + uint(q.x);
    if (pc.look.y == 0.0) {
        uint z = zbits[i];
        return z == NO_DEPTH ? vec2(0.0) : vec2(uintBitsToFloat(z), float(thick[i]) / THICK_SCALE);
    }
    return smoothed[i];
}

void main() {
    uint id = global_id();
    if (id >= pixel_count()) return;
    ivec2 q = ivec2(id % P.width, id / P.width);
    uint out_at = pc.look.y == 0.0 ? id : pixel_count() + id;
    vec2 c = input_at(q);
    if (c.x <= 0.0) {
        smoothed[out_at] = vec2(0.0);
        return;
    }
    float r = pc.fluid.w;
    float sigma = max(2.0 * r * abs(P.proj.y) * 0.5 * float(P.height) / c.x, 0.5);
    int reach = int(min(ceil(2.0 * sigma), pc.look.z));
    ivec2 axis = pc.look.y == 0.0 ? ivec2(1, 0) : ivec2(0, 1);
    ivec2 size = ivec2(P.width, P.height);
    vec2 sum = vec2(0.0);
    float wsum = 0.0;
    for (int k = -reach; k <= reach; ++k) {
        ivec2 s = q + axis * k;
        if (any(lessThan(s, ivec2(0))) || any(greaterThanEqual(s, size))) continue;
        vec2 v = input_at(s);
        if (v.x <= 0.0) continue;
        float dz = (v.x - c.x) / (2.0 * r);
        float w = exp(-0.5 * float(k * k) / (sigma * sigma) - 0.5 * dz * dz);
        sum += w * v;
        wsum += w;
    }
    smoothed[out_at] = sum / wsum;
}
