// Metaball rendering (seed 000, section 4): parameters, bindings, density functions and
// the per-pixel metaball lists. Mirrors src/render/metaball/gpu.rs (RenderParams).
// Defines: LIST 0 none | 1 abuffer | 2 sbuffer; SORTED 1: S-buffer ranges sorted by depth; DENSITY 0 blinn | 1 wyvill | 2 nishimura
// | 3 murakami; MATERIAL 0 phong | 1 glass | 2 tinted | 3 metal.
#ifndef METABALL_COMMON_GLSL
#define METABALL_COMMON_GLSL
#ifndef LIST
#define LIST 2
#endif
#ifndef DENSITY
#define DENSITY 1
#endif
#ifndef MATERIAL
#define MATERIAL 0
#endif
#ifndef SORTED
#define SORTED 0
#endif

struct RenderParams {
    mat4 view_proj;
    mat4 inv_view_proj;
    mat4 view;
    vec4 proj;      // x: P00, y: P11, z: near plane distance
    vec4 eye;       // xyz camera position, w = metaball radius R
    vec4 sun;       // xyz unit direction towards the sun, w = march step
    vec4 absorb;    // rgb absorption per unit length (tinted), w = index of refraction
    vec4 f0;        // rgb Fresnel reflectance at normal incidence (metals)
    vec4 base;      // rgb Phong colour, w = threshold T
    uint width;
    uint height;
    uint n;
    uint refine;
    uint depth;
    uint max_steps;
    uint list_capacity;  // S-buffer list or A-buffer pool entries
    uint offscreen_end;  // secondary samples off screen: 1 end the path, 0 use all metaballs
    uint sky_w;
    uint sky_h;
    uint debug;
    uint pad;
};
const uint NIL = 0xFFFFFFFFu;
// stats: [0] A-buffer node counter, [1] longest list, [2] list overflows, [3] off-screen
// secondary samples, [4] S-buffer fragments (its total)
// S-buffer: one array of W*H + 1: counts, scanned in place into starts, then advanced by
// the fill to each pixel's end, so pixel p's range is [p == 0 ? 0 : offsets[p-1], offsets[p]).
layout(std430, binding = 0) readonly buffer Params { RenderParams P; };  // binding 0
layout(std430, binding = 1) readonly buffer Centers { vec4 centers[]; };   // binding 1: xyz
layout(std430, binding = 2) readonly buffer Bounds { vec4 bounds[]; };     // binding 2: min, max
layout(std430, binding = 3) buffer Offsets { uint offsets[]; };            // binding 3: S offsets
layout(std430, binding = 4) buffer List { uint list[]; };                  // binding 4: S ranges
layout(std430, binding = 5) buffer Heads { uint heads[]; };                // binding 5: A heads
layout(std430, binding = 6) buffer Nodes { uvec2 nodes[]; };               // binding 6: A (id, next)
layout(std430, binding = 7) buffer Stats { uint stats[]; };                // binding 7
layout(std430, binding = 8) writeonly buffer Pixels { uint pixels[]; };    // binding 8: RGBA8
layout(std430, binding = 9) writeonly buffer Debug { vec4 debug_out[]; };  // binding 9: t, normal
layout(std430, binding = 10) readonly buffer Sky { uint sky[]; };          // binding 10: RGBA8
layout(std430, binding = 11) buffer Depths { float depths[]; };            // binding 11: view depths

uint range_start(uint p) { return p == 0u ? 0u : offsets[p - 1u]; }

// Distance in front of the eye along the view axis (1-Lipschitz in x).
float view_depth(vec3 x) {
    return -(P.view[0].z * x.x + P.view[1].z * x.y + P.view[2].z * x.z + P.view[3].z);
}

float radius() { return P.eye.w; }
float threshold() { return P.base.w; }

// D(r) from r^2, normalised to D(0) = 1, zero from R on (src/render/metaball/density.rs).
const float BLINN_A = 4.0;
float density2(float r2) {
    float R = radius();
    float q2 = r2 / (R * R);
    if (q2 >= 1.0) return 0.0;
#if DENSITY == 0
    float fl = exp(-BLINN_A);
    return (exp(-BLINN_A * q2) - fl) / (1.0 - fl);
#elif DENSITY == 1
    return 1.0 - 4.0 / 9.0 * q2 * q2 * q2 + 17.0 / 9.0 * q2 * q2 - 22.0 / 9.0 * q2;
#elif DENSITY == 2
    float q = sqrt(q2);
    return q <= 1.0 / 3.0 ? 1.0 - 3.0 * q2 : 1.5 * (1.0 - q) * (1.0 - q);
#else
    return (1.0 - q2) * (1.0 - q2);
#endif
}

// (dD/dr) / r = (dD/dq) / (q R^2), so grad D(|x - c|) = (x - c) * this; from r^2.
float density_grad_over_r(float r2) {
    float R = radius();
    float q2 = r2 / (R * R);
    if (q2 >= 1.0) return 0.0;
    float inv = 1.0 / (R * R);
#if DENSITY == 0
    float fl = exp(-BLINN_A);
    return -2.0 * BLINN_A * exp(-BLINN_A * q2) / (1.0 - fl) * inv;
#elif DENSITY == 1
    return (-24.0 / 9.0 * q2 * q2 + 68.0 / 9.0 * q2 - 44.0 / 9.0) * inv;
#elif DENSITY == 2
    float q = sqrt(q2);
    if (q <= 1.0 / 3.0) return -6.0 * inv;
    return q > 1e-12 ? -3.0 * (1.0 - q) / q * inv : 0.0;
#else
    return -4.0 * (1.0 - q2) * inv;
#endif
}

uint pixel_index(uvec2 p) { return p.y * P.width + p.x; }
#endif
