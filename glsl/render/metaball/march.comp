#version 450
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#if RAY_LANES > 1
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#endif
// Ray marching through the metaball field, one invocation per pixel (--ray-lanes: a group
// of RAY_LANES lanes per pixel, march_lanes.glsl). The primary ray
// marches the depth interval covered by the spheres of its pixel's list (LIST none: the
// fluid's bounds), sums only those metaballs, refines the hit by bisection and takes the
// normal from the analytic gradient. Glass and tinted trace reflection and refraction
// with an explicit stack; secondary samples read the list of the pixel they project to
// (off screen: every metaball, or the path ends).
#include "common/index.glsl"
#include "common.glsl"
#include "blocks.glsl"
#include "march_lanes.glsl"

// --lanes blocks and tiles: the 8 x 8 block this workgroup marches. RAY_LANES workgroups
// share a block, each taking 64 / RAY_LANES of its pixels in raster order.
uint march_block() { return group_id() / RAY_LANES; }
uvec2 march_block_origin() { return block_origin_of(march_block()); }
uvec2 march_block_pixel() {
    uint q = (group_id() % RAY_LANES) * (64u / RAY_LANES) + ray_group();
    return march_block_origin() + uvec2(q % 8u, q / 8u);
}

const uint ALL = 0xFFFFFFFEu;  // "every metaball" instead of a pixel's list
uint offscreen_samples = 0u;
uint longest = 0u;
// Per-ray counters (summed per subgroup and workgroup, then added to stats as 64-bit
// totals: add_counters).
uint n_rays = 0u, n_steps = 0u, n_evals = 0u, n_candidates = 0u;
// Grid samples of secondary rays passed over in empty cells, not evaluated (--occupancy).
uint n_skipped = 0u;
// The field and gradient evaluations this invocation makes one after another: the serial
// chain that sets a pixel's time (stats' serial_max and serial_mean).
uint n_serial = 0u;
// llvmpipe stops a batch's loops after about 65535 iterations in total (hang protection);
// every later loop then exits at once. Each loop below checks on exit that it ended by
// its own condition (CUT_UNLESS, the negated loop condition); pixels where one did not are counted in stats.budget_pixels, so a
// cut-short frame is reported, never silently wrong. Never set on a real GPU.
bool cut = false;
// --march lipschitz: the sorted S-buffer's depth window widened by this, so the sums also
// count the metaballs that can reach the next stretch of the ray (field_reach).
float reach_extra = 0.0;
#define CUT_UNLESS(ended) if (!(ended)) cut = true;

#if LIST == LIST_TILES
// --list tiles: one workgroup per 8 x 8 pixel block. The front STAGE pairs of the block's
// tile stay in shared memory for the sums; ball(s) reads pair s from there or memory.
const uint STAGE = 256u;
shared vec4 s_balls[STAGE];
uint stage_lo = 0u, stage_hi = 0u;
vec4 ball(uint s) { return s >= stage_lo && s < stage_hi ? s_balls[s - stage_lo] : tile_balls[s]; }
#endif

// Sum over the metaballs of pixel p (or ALL) of TERM(d), d = x - centre, into ACC; the
// terms summed into n_evals, counted from the walk's bounds where it has them (a count per
// term cost the S-buffer's march 7% on lavapipe, where it is vector arithmetic). Several
// metaballs per loop iteration (the inner loops unroll away), ALL_UNROLL over every metaball:
// llvmpipe's loop budget would otherwise cut short rays that take hundreds of samples over
// lists of hundreds (or, for none, all) metaballs.
#define ALL_UNROLL 32u
#define SUM_METABALLS(x, p, ACC, TERM) { \
    if (p == ALL) { \
        uint b_ = 0u; \
        for (; b_ < P.n; b_ += ALL_UNROLL) { \
            [[unroll]] for (uint u_ = 0u; u_ < ALL_UNROLL; ++u_) { \
                uint j_ = b_ + u_; \
                vec4 c_ = j_ < P.n ? centers[j_] : vec4(-1.0); \
                if (c_.w >= 0.0) { vec3 d = x - c_.xyz; ACC += TERM; n_evals++; } } } \
        CUT_UNLESS(!(b_ < P.n)) \
    } else { SUM_LIST(x, p, ACC, TERM) } }
#if LIST == LIST_ABUFFER
#define SUM_LIST(x, p, ACC, TERM) { \
    uint n_ = heads[p]; \
    for (; n_ != NIL;) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            if (n_ != NIL) { uvec2 e_ = nodes[n_]; vec3 d = x - centers[e_.x].xyz; ACC += TERM; n_evals++; n_ = e_.y; } } } \
    CUT_UNLESS(n_ == NIL) }
#elif LIST == LIST_SBUFFER && SORTED
// Sorted ranges: a binary search (on depths.comp's keys) finds the first centre at depth
// >= z - R, and the walk stops past z + R (the depth recomputed from the centre it loads
// anyway). Exact: |x - c| >= |depth(x) - depth(c)|, so every metaball outside the window
// is zero at x (the window has a 0.1% margin for rounding).
#define SUM_LIST(x, p, ACC, TERM) { \
    uint e_ = min(offsets[p], P.list_capacity); \
    float z_ = view_depth(x), r_ = radius() * 1.001 + 1e-6 + reach_extra; \
    uint lo_ = range_start(p), hi_ = e_; \
    while (lo_ < hi_) { \
        uint m_ = (lo_ + hi_) >> 1; \
        if (depths[list[m_]] < z_ - r_) lo_ = m_ + 1u; else hi_ = m_; } \
    CUT_UNLESS(!(lo_ < hi_)) \
    bool more_ = true; \
    uint b_ = lo_, end_ = e_; \
    for (; more_ && b_ < e_; b_ += 8u) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            uint s_ = b_ + u_; \
            if (more_ && s_ < e_) { \
                vec3 c_ = centers[list[s_]].xyz; \
                if (view_depth(c_) > z_ + r_) { more_ = false; end_ = s_; } \
                else { vec3 d = x - c_; ACC += TERM; } } } } \
    n_evals += end_ - lo_; \
    CUT_UNLESS(!(more_ && b_ < e_)) }
#elif LIST == LIST_SBUFFER
#define SUM_LIST(x, p, ACC, TERM) { \
    uint e_ = min(offsets[p], P.list_capacity); \
    uint b_ = range_start(p); \
    n_evals += e_ - min(b_, e_); \
    for (; b_ < e_; b_ += 8u) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            uint s_ = b_ + u_; \
            if (s_ < e_) { vec3 d = x - centers[list[s_]].xyz; ACC += TERM; } } } \
    CUT_UNLESS(!(b_ < e_)) }
#elif LIST == LIST_TILES
// The tile of pixel p holds every metaball whose billboard covers one of its pixels, sorted
// by depth: the sorted S-buffer's exact depth window, over the tile's range (ball()).
#define SUM_LIST(x, p, ACC, TERM) { \
    uvec2 t_ = tile_ranges[tile_of_pixel(p)]; \
    float z_ = view_depth(x), r_ = radius() * 1.001 + 1e-6 + reach_extra; \
    uint lo_ = t_.x, hi_ = t_.y; \
    while (lo_ < hi_) { \
        uint m_ = (lo_ + hi_) >> 1; \
        if (ball(m_).w < z_ - r_) lo_ = m_ + 1u; else hi_ = m_; } \
    CUT_UNLESS(!(lo_ < hi_)) \
    bool more_ = true; \
    uint b_ = lo_, end_ = t_.y; \
    for (; more_ && b_ < t_.y; b_ += 8u) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            uint s_ = b_ + u_; \
            if (more_ && s_ < t_.y) { \
                vec4 c_ = ball(s_); \
                if (c_.w > z_ + r_) { more_ = false; end_ = s_; } \
                else { vec3 d = x - c_.xyz; ACC += TERM; } } } } \
    n_evals += end_ - lo_; \
    CUT_UNLESS(!(more_ && b_ < t_.y)) }
#elif LIST == LIST_NONE
#define SUM_LIST(x, p, ACC, TERM)
#else
#error "LIST names no list mode"
#endif

float field(vec3 x, uint p) {
#if LIST == LIST_NONE
    p = ALL;
#endif
    float f = 0.0;
    n_serial++;
    SUM_METABALLS(x, p, f, density2(dot(d, d)))
    return f;
}

#if RAY_LANES == 1
// One invocation a ray: the field at BLOCK consecutive grid samples of a ray that all sum
// the same metaballs (every one under --list none; a primary ray's pixel list under the
// A-buffer and the unsorted S-buffer) in one pass, each centre loaded once for all of
// them (register blocking: the loads, not the terms, set the cost). Each sample's sum
// adds the same terms in the same order as field(): the same bits. One serial
// evaluation; `terms`: the metaballs each sample summed.
const uint BLOCK = 4u;
#if LIST == LIST_NONE || LIST == LIST_ABUFFER || (LIST == LIST_SBUFFER && SORTED == 0)
#define BLOCKED 1
#elif LIST == LIST_TILES || (LIST == LIST_SBUFFER && SORTED == 1)
#define BLOCKED 0
#else
#error "LIST names no list mode"
#endif
#define TERMS4(C) { \
    vec3 c4_ = (C), d0 = x0 - c4_, d1 = x1 - c4_, d2 = x2 - c4_, d3 = x3 - c4_; \
    f.x += density2(dot(d0, d0)); \
    f.y += density2(dot(d1, d1)); \
    f.z += density2(dot(d2, d2)); \
    f.w += density2(dot(d3, d3)); }
#if BLOCKED == 1
vec4 field_block(vec3 x0, vec3 x1, vec3 x2, vec3 x3, uint p, out uint terms) {
    vec4 f = vec4(0.0);
    uint m = 0u;
    n_serial++;
#if LIST == LIST_NONE
    p = ALL;
#endif
    if (p == ALL) {
        uint b_ = 0u;
        for (; b_ < P.n; b_ += ALL_UNROLL) {
            [[unroll]] for (uint u_ = 0u; u_ < ALL_UNROLL; ++u_) {
                uint j_ = b_ + u_;
                vec4 c_ = j_ < P.n ? centers[j_] : vec4(-1.0);
                if (c_.w >= 0.0) {
                    TERMS4(c_.xyz)
                    m++;
                }
            }
        }
        CUT_UNLESS(!(b_ < P.n))
    } else {
#if LIST == LIST_ABUFFER
        uint n_ = heads[p];
        for (; n_ != NIL;) {
            [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) {
                if (n_ != NIL) {
                    uvec2 e_ = nodes[n_];
                    TERMS4(centers[e_.x].xyz)
                    m++;
                    n_ = e_.y;
                }
            }
        }
        CUT_UNLESS(n_ == NIL)
#elif LIST == LIST_SBUFFER
        uint e_ = min(offsets[p], P.list_capacity), b_ = range_start(p);
        m = e_ - min(b_, e_);
        for (; b_ < e_; b_ += 8u) {
            [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) {
                uint s_ = b_ + u_;
                if (s_ < e_) TERMS4(centers[list[s_]].xyz)
            }
        }
        CUT_UNLESS(!(b_ < e_))
#elif LIST != LIST_NONE
#error "LIST names no blocked list"
#endif
    }
    terms = m;
    return f;
}
#endif
#endif

// The field at x and how many metaballs lie within R + reach of x: only those can be
// nonzero anywhere on the next `reach` of a ray through x.
vec2 field_reach(vec3 x, uint p, float reach) {
#if LIST == LIST_NONE
    p = ALL;
#endif
    float near2 = (radius() + reach) * (radius() + reach);
    vec2 f = vec2(0.0);
    n_serial++;
    reach_extra = reach;
    SUM_METABALLS(x, p, f, vec2(density2(dot(d, d)), dot(d, d) < near2 ? 1.0 : 0.0))
    reach_extra = 0.0;
    return f;
}

#include "march_split.glsl"

// The field's gradient at x: on a ray's lanes, each sums its share of the terms.
vec3 gradient(vec3 x, uint p) {
#if LIST == LIST_NONE
    p = ALL;
#endif
    vec3 g = vec3(0.0);
    n_serial++;
#if RAY_LANES == 1
    SUM_METABALLS(x, p, g, d * density_grad_over_r(dot(d, d)))
#elif RAY_LANES == 8 || RAY_LANES == 16 || RAY_LANES == 32
    SPLIT_METABALLS(x, p, g, d * density_grad_over_r(dot(d, d)))
    g = lanes_sum(g);
#else
#error "RAY_LANES is 1, 8, 16 or 32"
#endif
    return g;
}

// The pixel whose list covers point x, NIL when x projects off screen or behind the eye.
uint project(vec3 x) {
    vec4 c = P.view_proj * vec4(x, 1.0);
    if (c.w <= 1e-6) return NIL;
    vec2 ndc = c.xy / c.w;
    vec2 s = (ndc * 0.5 + 0.5) * vec2(P.width, P.height);
    if (any(lessThan(s, vec2(0.0))) || s.x >= float(P.width) || s.y >= float(P.height)) return NIL;
    return pixel_index(uvec2(s));
}

vec2 ray_box(vec3 o, vec3 d, vec3 lo, vec3 hi) {
    vec3 inv = 1.0 / d;
    vec3 a = (lo - o) * inv, b = (hi - o) * inv;
    return vec2(max(max(min(a, b).x, min(a, b).y), max(min(a, b).z, 0.0)), min(min(max(a, b).x, max(a, b).y), max(a, b).z));
}

#if LIST != LIST_TILES
// The depth interval the spheres of pixel p cover along the primary ray (the S-buffer's
// range split over the ray's lanes; min and max meet exactly in any order).
vec2 list_interval(vec3 o, vec3 d, uint p) {
    float R2 = radius() * radius();
    vec2 iv = vec2(1e30, -1e30);
    uint len = 0u;
#if LIST == LIST_ABUFFER
    uint node = heads[p];
    for (; node != NIL; node = nodes[node].y) {
        vec3 oc = o - centers[nodes[node].x].xyz;
        len++;
#elif LIST == LIST_SBUFFER
    uint s = range_start(p), e = min(offsets[p], P.list_capacity);
    len = e - min(s, e);
    for (s += ray_lane(); s < e; s += RAY_LANES) {
        vec3 oc = o - centers[list[s]].xyz;
#elif LIST == LIST_NONE
    for (uint j = 0u; j < 0u; ++j) {
        vec3 oc = o;
#else
#error "LIST names no list mode"
#endif
        float b = dot(oc, d);
        float disc = b * b - (dot(oc, oc) - R2);
        if (disc > 0.0) { float q = sqrt(disc); iv = vec2(min(iv.x, -b - q), max(iv.y, -b + q)); }
    }
#if LIST == LIST_ABUFFER
    CUT_UNLESS(node == NIL)
#elif LIST == LIST_SBUFFER
    CUT_UNLESS(!(s < e))
#elif LIST != LIST_NONE
#error "LIST names no list mode"
#endif
    iv = vec2(lanes_min(iv.x), lanes_max(iv.y));
    longest = max(longest, len);
    n_candidates += len;
    return vec2(max(iv.x, 0.0), iv.y);
}
#endif

#if LIST == LIST_TILES
// list_interval over the block's tile, its pairs staged in shared memory in batches of 64
// (every invocation of the group calls this: it holds barriers); then the tile's front
// STAGE pairs are staged for the sums. Candidates: the tile's pairs.
vec2 tile_interval(vec3 o, vec3 d) {
    // Blocks past the frame (a dispatch split over y) stage nothing.
    uvec2 origin = march_block_origin();
    uvec2 range = origin.y < P.height ? tile_ranges[tile_of(origin)] : uvec2(0u);
    float R2 = radius() * radius();
    vec2 iv = vec2(1e30, -1e30);
    uint l = gl_LocalInvocationIndex;
    uint base = range.x;
    for (; base < range.y; base += 64u) {
        barrier();
        if (base + l < range.y) s_balls[l] = tile_balls[base + l];
        barrier();
        uint m = min(64u, range.y - base);
        [[unroll]] for (uint j = 0u; j < 64u; ++j) {
            vec3 oc = o - s_balls[j].xyz;
            float b = dot(oc, d);
            float disc = b * b - (dot(oc, oc) - R2);
            if (j < m && disc > 0.0) {
                float q = sqrt(disc);
                iv = vec2(min(iv.x, -b - q), max(iv.y, -b + q));
            }
        }
    }
    CUT_UNLESS(!(base < range.y))
    barrier();
    for (uint k = l; k < STAGE; k += 64u) {
        if (range.x + k < range.y) s_balls[k] = tile_balls[range.x + k];
    }
    barrier();
    stage_lo = range.x;
    stage_hi = min(range.y, range.x + STAGE);
    uint len = range.y - range.x;
    longest = max(longest, len);
    n_candidates += len;
    return vec2(max(iv.x, 0.0), iv.y);
}
#endif

vec3 box_lo() { return bounds[0].xyz - vec3(radius()); }
vec3 box_hi() { return bounds[1].xyz + vec3(radius()); }

#include "occupancy.glsl"
// --occupancy on: a secondary ray outside the fluid passes over grid samples in cells no
// metaball reaches (occupancy.glsl: the field is 0 < T there, so no sample crosses T).
// Primary rays march their list's interval, and rays inside cross T where the field is 0.
bool skips_empty(uint pixel, bool inside) { return P.occupancy != 0u && pixel == NIL && !inside; }
// Whether x lies in an empty cell; the cell last read and what it held are kept, so a ray
// loads each cell it crosses once.
OccGrid occ = OccGrid(vec3(0.0), vec3(0.0), uvec3(0u));
bool occ_read = false, occ_last_empty = false;
uint occ_last = NIL;
bool in_empty_cell(vec3 x) {
    if (!occ_read) {
        occ = occ_header();
        occ_read = true;
    }
    uint c = occ_cell(occ, x);
    if (c == NIL) return false;
    if (c != occ_last) {
        occ_last = c;
        occ_last_empty = occupancy[OCC_CELLS + c] == 0u;
    }
    return occ_last_empty;
}
// A march's samples: `taken` grid samples up to its exit, `skipped` of them passed over.
void count_samples(uint taken, uint skipped) {
    n_steps += taken - skipped;
    n_skipped += skipped;
}

#include "march_ray.glsl"

vec3 normal_at(vec3 x, uint pixel) {
    uint p = pixel == NIL ? project(x) : pixel;
    if (p == NIL) p = ALL;
    vec3 g = gradient(x, p);
    float l = length(g);
    return l > 0.0 ? -g / l : vec3(0.0, 1.0, 0.0);
}

#include "render/shading.glsl"

#include "march_counters.glsl"

struct Path { vec3 o; vec3 d; vec3 w; uint depth; bool inside; vec2 cone; };

// Glass and tinted branch into two paths per hit and keep the ones waiting on a stack;
// Phong (the primary ray alone) and the metals (each reflection replaces its path) follow
// one path at a time. The stack is STACK named slots, not an array indexed at run time
// (which a GPU compiler puts in local memory even when one entry is used): STACK is the
// recursion depth + 1, the most a depth-first walk holds (a waiting sibling per level
// and a hit's two paths), so it never overflows.
#if MATERIAL == MATERIAL_GLASS || MATERIAL == MATERIAL_TINTED
#define STACKED 1
#include "march_stack.glsl"
#elif MATERIAL == MATERIAL_PHONG || MATERIAL == MATERIAL_METAL
#define STACKED 0
#else
#error "MATERIAL names no material"
#endif

// One pixel's colour (and depth, debug output); invocations past the frame return at
// once, except that tiles' join the barriers of their block's staging first.
void march_pixel() {
#if LIST == LIST_TILES || LANES == LANES_BLOCKS
    // One workgroup per 8 x 8 block (tiles: march.comp stages the block's tile).
    uvec2 pix = march_block_pixel();
    bool valid = pix.x < P.width && pix.y < P.height;
    uint id = valid ? pixel_index(pix) : 0u;
#elif LANES == LANES_ROWS
    uint id = group_id() * (gl_WorkGroupSize.x / RAY_LANES) + ray_group();
    bool valid = id < P.width * P.height;
    uvec2 pix = uvec2(id % P.width, id / P.width);
#else
#error "LANES names no lane layout"
#endif
#if LIST != LIST_TILES
    if (!valid) return;
#endif
    vec2 ndc = (vec2(pix) + 0.5) / vec2(P.width, P.height) * 2.0 - 1.0;
    vec4 a = P.inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec4 b = P.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 o = P.eye.xyz;
    vec3 d = normalize(b.xyz / b.w - a.xyz / a.w);
    // The pixel's ray cone: no width at the eye, the angle to the next pixel's ray.
    vec4 a1 = P.inv_view_proj * vec4(ndc + vec2(2.0 / float(P.width), 0.0), 0.0, 1.0);
    vec4 b1 = P.inv_view_proj * vec4(ndc + vec2(2.0 / float(P.width), 0.0), 1.0, 1.0);
    vec2 cone = vec2(0.0, length(normalize(b1.xyz / b1.w - a1.xyz / a1.w) - d));

#if LIST == LIST_NONE
    vec2 iv = ray_box(o, d, box_lo(), box_hi());
    n_candidates = P.n;
#elif LIST == LIST_TILES
    vec2 iv = tile_interval(o, d);
    if (!valid) return;
#else
    vec2 iv = list_interval(o, d, id);
#endif
    // Rays stop at the opaque layer, which shows where no fluid is in front of it.
    float t_opaque = opaque_t(id, ndc, o, d);
    iv.y = min(iv.y, t_opaque);
    vec3 color = vec3(0.0);
    vec4 dbg = vec4(-1.0, 0.0, 0.0, 0.0);
#if STACKED
    push(Path(o, d, vec3(1.0), 0u, false, cone));
    while (sp > 0) {
        Path r = pop();
#else
    Path r = Path(o, d, vec3(1.0), 0u, false, cone);
    bool more = true;
    while (more) {
        more = false;  // a metal's reflection sets it again
#endif
        bool primary = r.depth == 0u;
        vec2 span = primary ? iv : ray_box(r.o, r.d, box_lo(), box_hi());
#if MARCH == MARCH_LIPSCHITZ
        // Secondary rays sample other pixels' lists: no bound holds across them. Without
        // lists every sample sums every metaball and the bound holds on any ray, unless
        // off-screen samples end paths (then every sample must be projected).
#if LIST == LIST_NONE
        bool bounded = primary || P.offscreen_end == 0u;
#elif LIST == LIST_ABUFFER || LIST == LIST_SBUFFER || LIST == LIST_TILES
        bool bounded = primary;
#else
#error "LIST names no list mode"
#endif
        float t = span.x > span.y ? -1.0
            : bounded ? march_lipschitz(r.o, r.d, span.x, span.y, r.inside, primary ? id : NIL)
            : march(r.o, r.d, span.x, span.y, r.inside, NIL);
#elif MARCH == MARCH_FIXED
        float t = span.x <= span.y ? march(r.o, r.d, span.x, span.y, r.inside, primary ? id : NIL) : -1.0;
#else
#error "MARCH is MARCH_FIXED or MARCH_LIPSCHITZ"
#endif
        if (t < 0.0) {
            // Left the fluid's bounds (or the screen, with offscreen_end): the sky, or the
            // opaque layer for a primary ray that reached it. Secondary rays see the sky.
            vec3 behind = primary && t_opaque < 1e30
                ? pow(unpackUnorm4x8(opaque[id]).rgb, vec3(2.2))
                : sky_color(r.d, r.cone);
            color += r.w * behind;
            continue;
        }
        vec3 x = r.o + r.d * t;
        vec3 n = normal_at(x, primary ? id : NIL);
        vec2 hit_cone = cone_at(r.cone, t);
        if (primary) dbg = vec4(t, n);
#if MATERIAL == MATERIAL_PHONG
        color += r.w * phong(n, -r.d);
#elif MATERIAL == MATERIAL_GLASS || MATERIAL == MATERIAL_TINTED || MATERIAL == MATERIAL_METAL
        vec3 w = r.w;
#if MATERIAL == MATERIAL_TINTED
        if (r.inside) w *= exp(-P.absorb.rgb * t);  // Beer-Lambert along the inside path
#endif
        vec3 nn = r.inside ? -n : n;  // facing the incoming ray
        float cos_i = clamp(-dot(r.d, nn), 0.0, 1.0);
        vec3 rd = reflect(r.d, nn);
        // Just past the refined hit's error (step / 2^I): the new path starts on its side
        // of the surface. A fixed share of R was up to a quarter of a small sphere's radius.
        float eps = 1.5 * P.sun.w / float(1u << min(P.refine, 20u));
#if MATERIAL == MATERIAL_METAL
        vec3 F = P.f0.rgb + (1.0 - P.f0.rgb) * pow(1.0 - cos_i, 5.0);
        Path refl = Path(x + nn * eps, rd, w * F, r.depth + 1u, r.inside, cone_bent(hit_cone, P.eye.w, 2.0));
        if (r.depth + 1u > P.depth) color += refl.w * sky_color(rd, refl.cone);
        else {
            r = refl;
            more = true;
        }
#else
        float n1 = r.inside ? P.absorb.w : 1.0, n2 = r.inside ? 1.0 : P.absorb.w;
        vec3 td = refract(r.d, nn, n1 / n2);
        float F = dot(td, td) == 0.0 ? 1.0 : fresnel_dielectric(cos_i, n1, n2);
        Path refl = Path(x + nn * eps, rd, w * F, r.depth + 1u, r.inside, cone_bent(hit_cone, P.eye.w, 2.0));
        Path refr = Path(x - nn * eps, normalize(td), w * (1.0 - F), r.depth + 1u, !r.inside, cone_bent(hit_cone, P.eye.w, 1.0));
        bool deep = r.depth + 1u > P.depth;
        if (deep || sp >= STACK) color += refl.w * sky_color(rd, refl.cone); else push(refl);
        if (F < 1.0) {
            if (deep || sp >= STACK) color += refr.w * sky_color(refr.d, refr.cone); else push(refr);
        }
#endif
#else
#error "MATERIAL names no material"
#endif
    }
#if STACKED
    CUT_UNLESS(!(sp > 0))
#else
    CUT_UNLESS(!more)
#endif
    // Every lane of the ray's group holds the same colour: its first writes it.
    bool cut_any = lanes_ballot(cut) != 0u;
    if (ray_lane() != 0u) return;
    color = with_tank(color, o, d, min(dbg.x >= 0.0 ? dbg.x : 1e30, t_opaque));
    color = pow(clamp(color, 0.0, 1.0), vec3(1.0 / 2.2));
    pixels[id] = packUnorm4x8(vec4(color, 1.0));
    if (P.opaque != 0u) {
        // Layers drawn over the picture (blended particles) are depth-tested against it.
        float z = uintBitsToFloat(opaque[P.width * P.height + id]);
        if (dbg.x >= 0.0) {
            vec4 c = P.view_proj * vec4(o + d * dbg.x, 1.0);
            z = min(z, c.z / c.w);
        }
        scene_depth[id] = z;
    }
    if (P.debug != 0u) debug_out[id] = dbg;
    // Not a counter: a cut-short pixel makes a wrong frame, reported in every mode.
    if (cut_any) atomicAdd(stats.budget_pixels, 1u);
}

void main() {
    march_pixel();
    // The group's per-ray counts are its first lane's (every lane counted the same rays);
    // terms, off-screen samples and serial chains are each lane's own.
    if (ray_lane() != 0u) n_rays = n_steps = n_candidates = n_skipped = 0u;
    add_counters();  // every invocation: WORKGROUP's barriers
}
