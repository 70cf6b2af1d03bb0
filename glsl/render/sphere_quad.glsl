// One screen-aligned quad per sphere covering the exact screen-space bounds of the sphere
// (tangent lines from the eye per axis), widened by one pixel so the pixel containing the
// projection of any point inside the sphere gets a fragment, and rounded out to whole
// pixels. Spheres crossing the near plane cover the screen; spheres behind it none. The
// includer declares P (RenderParams).
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
    precise float e1 = scale * t1.x / t1.y, e2 = scale * t2.x / t2.y;
    return vec2(min(e1, e2), max(e1, e2));
}

// The pixels [x0, x1) x [y0, y1) (xy, zw) of the sphere at world `center` with radius r:
// its exact screen bounds widened by one pixel and rounded outward to whole pixels, within
// the frame; empty (x0 >= x1) for a dead slot or a sphere behind the eye, the whole frame
// for one crossing the near plane. Whole-pixel edges lie half a pixel from every pixel
// centre, so rasterising the quad covers exactly this rectangle whatever the rasterizer's
// snapping and tie rule, and compute binning (render/metaball/tile_bin.comp) takes the same
// one. `precise`: no contraction, so every stage computes the same bits.
uvec4 sphere_rect(vec3 center, float r, bool dead) {
    precise vec3 c = (P.view * vec4(center, 1.0)).xyz;
    precise float w = -c.z;  // depth in front of the eye
    vec2 size = vec2(P.width, P.height);
    if (w + r <= P.proj.z || dead) return uvec4(0u);
    if (w - r <= P.proj.z) return uvec4(0u, 0u, P.width, P.height);
    precise vec2 bx = axis_bounds(c.x, w, r, P.proj.x);
    precise vec2 by = axis_bounds(c.y, w, r, P.proj.y);
    precise vec2 lo = (vec2(bx.x, by.x) * 0.5 + 0.5) * size - 1.0;
    precise vec2 hi = (vec2(bx.y, by.y) * 0.5 + 0.5) * size + 1.0;
    vec2 a = clamp(floor(lo), vec2(0.0), size), b = clamp(ceil(hi), vec2(0.0), size);
    return uvec4(uvec2(a), uvec2(b));
}

// Clip position of corner `corner` (0..5) of the quad over `sphere_rect`; `dead`: a slot
// without a particle (no quad).
vec4 sphere_quad(vec3 center, float r, bool dead, uint corner) {
    uvec4 rc = sphere_rect(center, r, dead);
    if (rc.x >= rc.z || rc.y >= rc.w) return vec4(2.0, 2.0, 0.5, 1.0);  // no pixels: culled
    vec2 size = vec2(P.width, P.height);
    vec2 lo = vec2(rc.xy) / size * 2.0 - 1.0, hi = vec2(rc.zw) / size * 2.0 - 1.0;
    return vec4(mix(lo, hi, QUAD_CORNERS[corner]), 0.5, 1.0);
}
#endif
