#version 450
// Screen-space fluid, normals from the smoothed depth: each pixel's world position from
// its depth, differences to the neighbour with the smaller depth step per axis (so the
// silhouettes take the inner side), the normal their cross product facing the eye; the
// G-buffer takes depth, normal and thickness.
#include "common/index.glsl"
#include "common.glsl"

float depth_at(ivec2 q) {
    if (any(lessThan(q, ivec2(0))) || q.x >= int(P.width) || q.y >= int(P.height)) return 0.0;
    return smoothed[pixel_count() + uint(q.y) * P.width + uint(q.x)].x;
}

vec3 world_at(ivec2 q, float z) {
    vec3 d = primary_dir(vec2(q));
    return P.eye.xyz + d * (z / depth_rate(d));
}

// The derivative of the position along `axis` from the better-matching neighbour.
vec3 derivative(ivec2 q, float z, vec3 x, ivec2 axis) {
    float zl = depth_at(q - axis), zr = depth_at(q + axis);
    bool l = zl > 0.0, r = zr > 0.0;
    if (r && (!l || abs(zr - z) <= abs(z - zl))) return world_at(q + axis, zr) - x;
    if (l) return x - world_at(q - axis, zl);
    return vec3(0.0);
}

void main() {
    uint id = global_id();
    if (id >= pixel_count()) return;
    ivec2 q = ivec2(id % P.width, id / P.width);
    float z = depth_at(q);
    if (z <= 0.0) {
        gbuf[2u * id] = vec4(0.0);
        gbuf[2u * id + 1u] = vec4(0.0);
        return;
    }
    vec3 x = world_at(q, z);
    vec3 n = cross(derivative(q, z, x, ivec2(1, 0)), derivative(q, z, x, ivec2(0, 1)));
    vec3 to_eye = P.eye.xyz - x;
    float l = length(n);
    n = l > 1e-12 ? n / l : normalize(to_eye);
    if (dot(n, to_eye) < 0.0) n = -n;
    gbuf[2u * id] = vec4(z, n);
    gbuf[2u * id + 1u] = vec4(smoothed[pixel_count() + id].y, 0.0, 0.0, 0.0);
}
