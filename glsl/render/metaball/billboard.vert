#version 450
// One screen-aligned quad per metaball covering the exact screen-space bounds of its
// sphere of radius R (tangent lines from the eye per axis), widened by one pixel so the
// pixel containing the projection of any point inside the sphere gets a fragment.
// Spheres crossing the near plane cover the screen; spheres behind it none.
// Every list pass draws these quads against the same depth: bit-equal positions.
invariant gl_Position;
#include "common.glsl"
layout(location = 0) flat out uint v_id;
const vec2 corners[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));

// NDC extent along one view axis of the circle at (a, depth w) with radius r, w - r > 0.
vec2 axis_bounds(float a, float w, float r, float scale) {
    float d2 = a * a + w * w;
    float d = sqrt(d2);
    float cs = sqrt(max(d2 - r * r, 0.0)) / d, sn = r / d;
    vec2 t1 = cs * vec2(cs * a - sn * w, sn * a + cs * w);
    vec2 t2 = cs * vec2(cs * a + sn * w, -sn * a + cs * w);
    float e1 = scale * t1.x / t1.y, e2 = scale * t2.x / t2.y;
    return vec2(min(e1, e2), max(e1, e2));
}

void main() {
    uint id = gl_InstanceIndex;
    v_id = id;
    vec3 c = (P.view * vec4(centers[id].xyz, 1.0)).xyz;
    float r = radius();
    float w = -c.z;  // depth in front of the eye
    vec2 lo, hi;
    if (w + r <= P.proj.z || centers[id].w < 0.0) {  // behind the eye, or a dead slot
        gl_Position = vec4(2.0, 2.0, 0.5, 1.0);  // behind the eye: degenerate, culled
        return;
    } else if (w - r <= P.proj.z) {
        lo = vec2(-1.0);
        hi = vec2(1.0);
    } else {
        vec2 bx = axis_bounds(c.x, w, r, P.proj.x);
        vec2 by = axis_bounds(c.y, w, r, P.proj.y);
        vec2 px = 2.0 / vec2(P.width, P.height);
        lo = vec2(bx.x, by.x) - px;
        hi = vec2(bx.y, by.y) + px;
    }
    gl_Position = vec4(mix(lo, hi, corners[gl_VertexIndex]), 0.5, 1.0);
}
