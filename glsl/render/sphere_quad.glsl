// One screen-aligned quad per sphere covering the exact screen-space bounds of the sphere
// (tangent lines from the eye per axis), widened by one pixel so the pixel containing the
// projection of any point inside the sphere gets a fragment. Spheres crossing the near
// plane cover the screen; spheres behind it none. The includer declares P (RenderParams).
#ifndef SPHERE_QUAD_GLSL
#define SPHERE_QUAD_GLSL
const vec2 QUAD_CORNERS[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));

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

// Clip position of corner `corner` (0..5) of the quad of the sphere at world `center` with
// radius r; `dead`: a slot without a particle (no quad).
vec4 sphere_quad(vec3 center, float r, bool dead, uint corner) {
    vec3 c = (P.view * vec4(center, 1.0)).xyz;
    float w = -c.z;  // depth in front of the eye
    vec2 lo, hi;
    if (w + r <= P.proj.z || dead) {
        return vec4(2.0, 2.0, 0.5, 1.0);  // behind the eye: degenerate, culled
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
    return vec4(mix(lo, hi, QUAD_CORNERS[corner]), 0.5, 1.0);
}
#endif
