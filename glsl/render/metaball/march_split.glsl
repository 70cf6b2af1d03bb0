// Sums split over a ray's lanes (march.comp, RAY_LANES > 1): lane j takes every
// RAY_LANES-th term of pixel p's list (or of ALL) from the j-th, counting each in n_evals,
// and lanes_sum adds the lanes' parts. The lanes' counts sum to the serial walk's: a sorted
// walk's window ends at one index for every lane. The gradient at a hit is summed so (the
// march's samples are one lane's each); its terms add in another order than the serial
// sum's, so normals agree to rounding and pictures within the golden tolerance.
#ifndef RENDER_METABALL_MARCH_SPLIT_GLSL
#define RENDER_METABALL_MARCH_SPLIT_GLSL
#if RAY_LANES > 1
#define SPLIT_STEP (8u * RAY_LANES)
#define SPLIT_METABALLS(x, p, ACC, TERM) { \
    uint l_ = ray_lane(); \
    if (p == ALL) { \
        uint b_ = l_; \
        for (; b_ < P.n; b_ += SPLIT_STEP) { \
            [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
                uint j_ = b_ + u_ * RAY_LANES; \
                vec4 c_ = j_ < P.n ? centers[j_] : vec4(-1.0); \
                if (c_.w >= 0.0) { vec3 d = x - c_.xyz; ACC += TERM; n_evals++; } } } \
        CUT_UNLESS(!(b_ < P.n)) \
    } else { SPLIT_LIST(x, p, ACC, TERM) } }
#if LIST == LIST_ABUFFER
#define SPLIT_LIST(x, p, ACC, TERM) { \
    uint n_ = heads[p], k_ = 0u; \
    for (; n_ != NIL;) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            if (n_ != NIL) { \
                uvec2 e_ = nodes[n_]; \
                if (k_ % RAY_LANES == l_) { vec3 d = x - centers[e_.x].xyz; ACC += TERM; n_evals++; } \
                k_++; n_ = e_.y; } } } \
    CUT_UNLESS(n_ == NIL) }
#elif LIST == LIST_SBUFFER && SORTED
#define SPLIT_LIST(x, p, ACC, TERM) { \
    uint e_ = min(offsets[p], P.list_capacity); \
    float z_ = view_depth(x), r_ = radius() * 1.001 + 1e-6 + reach_extra; \
    uint lo_ = range_start(p), hi_ = e_; \
    while (lo_ < hi_) { \
        uint m_ = (lo_ + hi_) >> 1; \
        if (depths[list[m_]] < z_ - r_) lo_ = m_ + 1u; else hi_ = m_; } \
    CUT_UNLESS(!(lo_ < hi_)) \
    bool more_ = true; \
    uint b_ = lo_ + l_; \
    for (; more_ && b_ < e_; b_ += SPLIT_STEP) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            uint s_ = b_ + u_ * RAY_LANES; \
            if (more_ && s_ < e_) { \
                vec3 c_ = centers[list[s_]].xyz; \
                if (view_depth(c_) > z_ + r_) more_ = false; \
                else { vec3 d = x - c_; ACC += TERM; n_evals++; } } } } \
    CUT_UNLESS(!(more_ && b_ < e_)) }
#elif LIST == LIST_SBUFFER
#define SPLIT_LIST(x, p, ACC, TERM) { \
    uint e_ = min(offsets[p], P.list_capacity); \
    uint b_ = range_start(p) + l_; \
    for (; b_ < e_; b_ += SPLIT_STEP) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            uint s_ = b_ + u_ * RAY_LANES; \
            if (s_ < e_) { vec3 d = x - centers[list[s_]].xyz; ACC += TERM; n_evals++; } } } \
    CUT_UNLESS(!(b_ < e_)) }
#elif LIST == LIST_TILES
#define SPLIT_LIST(x, p, ACC, TERM) { \
    uvec2 t_ = tile_ranges[tile_of_pixel(p)]; \
    float z_ = view_depth(x), r_ = radius() * 1.001 + 1e-6 + reach_extra; \
    uint lo_ = t_.x, hi_ = t_.y; \
    while (lo_ < hi_) { \
        uint m_ = (lo_ + hi_) >> 1; \
        if (ball(m_).w < z_ - r_) lo_ = m_ + 1u; else hi_ = m_; } \
    CUT_UNLESS(!(lo_ < hi_)) \
    bool more_ = true; \
    uint b_ = lo_ + l_; \
    for (; more_ && b_ < t_.y; b_ += SPLIT_STEP) { \
        [[unroll]] for (uint u_ = 0u; u_ < 8u; ++u_) { \
            uint s_ = b_ + u_ * RAY_LANES; \
            if (more_ && s_ < t_.y) { \
                vec4 c_ = ball(s_); \
                if (c_.w > z_ + r_) more_ = false; \
                else { vec3 d = x - c_.xyz; ACC += TERM; n_evals++; } } } } \
    CUT_UNLESS(!(more_ && b_ < t_.y)) }
#elif LIST == LIST_NONE
#define SPLIT_LIST(x, p, ACC, TERM)
#else
#error "LIST names no list mode"
#endif
#endif
#endif
