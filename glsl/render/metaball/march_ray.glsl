// The march along one ray (march.comp includes it after the field): the bisection of a
// crossing, the fixed-step march and the Lipschitz march, serial (RAY_LANES 1: one
// invocation per ray) or over a group of RAY_LANES lanes (march_lanes.glsl), which takes
// the serial march's samples and bisection midpoints, so its hits are bit for bit the same.
// Secondary rays outside the fluid pass over samples in cells the occupancy grid proves
// empty (P.occupancy; occupancy.glsl): their field is 0 < T, so the hits stay the same.
#ifndef RENDER_METABALL_MARCH_RAY_GLSL
#define RENDER_METABALL_MARCH_RAY_GLSL
#if RAY_LANES == 1
// The crossing between ray parameters a (this side of T) and b (across it), refined by
// P.refine bisection steps; pixel as in `march` (NIL: each sample projects).
float bisect(vec3 o, vec3 d, float a, float b, bool inside, uint pixel) {
    float T = threshold();
    uint k = 0u;
    for (; k < P.refine; ++k) {
        float m = 0.5 * (a + b);
        vec3 xm = o + d * m;
        uint pm = pixel == NIL ? project(xm) : pixel;
        if (pm == NIL) pm = ALL;
        if ((field(xm, pm) >= T) != inside) b = m; else a = m;
    }
    CUT_UNLESS(!(k < P.refine))
    n_steps += k;  // the samples taken, counted once (not per sample)
    return b;
}

#if BLOCKED == 1
// `march_one` below, BLOCK grid samples at a time (field_block: each metaball loaded once
// for all of them), where every sample sums the same metaballs: every ray under --list
// none, primary rays (their pixel's list) under the A-buffer and unsorted S-buffer. Each
// sample's projection, off-screen end and empty cell are taken in the order the
// one-sample march takes them, and the first sample across T is its first: the same
// hits, with its counts (rays, samples, terms, off-screen samples; the samples past the
// exit are speculation, not counted) and one serial evaluation a block.
float march_block(vec3 o, vec3 d, float t0, float t1, bool inside, uint pixel) {
    float T = threshold(), step = P.sun.w;
    float t = ceil(t0 / step) * step;
    float prev = max(t - step, 0.0);
    uint i = 0u, skipped = 0u;
    bool skips = skips_empty(pixel, inside);
    n_rays++;
    bool more = true;
    for (; more;) {
        float tk[BLOCK];
        vec3 xk[BLOCK];
        bool off[BLOCK], empty[BLOCK];
        uint valid = 0u;
        bool any = false;
        float tj = t;
        [[unroll]] for (uint k = 0u; k < BLOCK; ++k) {
            tk[k] = tj;
            xk[k] = o + d * tj;
            tj += step;
            bool in_ray = i + k < P.max_steps && tk[k] <= t1;
            valid += in_ray ? 1u : 0u;
            off[k] = in_ray && pixel == NIL && project(xk[k]) == NIL;
            empty[k] = in_ray && !(off[k] && P.offscreen_end != 0u) && skips && in_empty_cell(xk[k]);
            any = any || (in_ray && !empty[k] && !(off[k] && P.offscreen_end != 0u));
        }
        uint m = 0u;
        vec4 f = vec4(0.0);
        if (any) f = field_block(xk[0], xk[1], xk[2], xk[3], pixel == NIL ? ALL : pixel, m);
        uint used = 0u;  // samples evaluated up to the exit
        [[unroll]] for (uint k = 0u; k < BLOCK; ++k) {
            if (more && k < valid) {
                if (off[k]) {
                    offscreen_samples++;
                    if (P.offscreen_end != 0u) {
                        n_evals += m * used;
                        count_samples(i + k + 1u, skipped);
                        return -2.0;
                    }
                }
                if (empty[k]) {
                    skipped++;
                } else {
                    used++;
                    if ((f[k] >= T) != inside) {
                        n_evals += m * used;
                        count_samples(i + k + 1u, skipped);
                        return bisect(o, d, k == 0u ? prev : tk[k - 1u], tk[k], inside, pixel);
                    }
                }
            }
        }
        n_evals += m * used;
        if (valid < BLOCK) {
            count_samples(i + valid, skipped);
            more = false;
        } else {
            i += BLOCK;
            prev = tk[BLOCK - 1u];
            t = tj;
        }
    }
    CUT_UNLESS(!more)
    return -1.0;
}
#endif

// March [t0, t1]: entering (inside = false) or leaving the fluid. pixel: the primary
// ray's list, or NIL for secondary rays (each sample projects). Returns the hit t or -1;
// -2 when a secondary sample left the screen and paths end there. Samples sit on the
// grid t = k * step from the ray's origin, so every list variant (whose intervals start
// at different t0) takes the same samples and bisects the same steps.
float march_one(vec3 o, vec3 d, float t0, float t1, bool inside, uint pixel) {
    float T = threshold(), step = P.sun.w;
    float t = ceil(t0 / step) * step;
    float prev = max(t - step, 0.0);
    uint i = 0u, skipped = 0u;
    bool skips = skips_empty(pixel, inside);
    n_rays++;
    // The samples are counted once at each exit (i + 1 where sample i ends the march),
    // less those passed over in empty cells (counted apart).
    for (; i < P.max_steps && t <= t1; ++i) {
        vec3 x = o + d * t;
        uint p = pixel;
        if (pixel == NIL) {
            p = project(x);
            if (p == NIL) {
                offscreen_samples++;
                if (P.offscreen_end != 0u) {
                    count_samples(i + 1u, skipped);
                    return -2.0;
                }
                p = ALL;
            }
            if (skips && in_empty_cell(x)) {
                skipped++;
                prev = t;
                t += step;
                continue;
            }
        }
        if ((field(x, p) >= T) != inside) {
            count_samples(i + 1u, skipped);
            return bisect(o, d, prev, t, inside, pixel);
        }
        prev = t;
        t += step;
    }
    CUT_UNLESS(!(i < P.max_steps && t <= t1))
    count_samples(i, skipped);
    return -1.0;
}

// A ray's march: a block of samples at a time where they all sum the same metaballs.
float march(vec3 o, vec3 d, float t0, float t1, bool inside, uint pixel) {
#if LIST == LIST_NONE
    return march_block(o, d, t0, t1, inside, pixel);
#elif BLOCKED == 1
    return pixel != NIL ? march_block(o, d, t0, t1, inside, pixel)
                        : march_one(o, d, t0, t1, inside, pixel);
#elif BLOCKED == 0
    return march_one(o, d, t0, t1, inside, pixel);
#else
#error "BLOCKED is 0 or 1"
#endif
}

#if MARCH == MARCH_LIPSCHITZ
// `march` on the same grid for a primary ray, whose pixel's list holds every metaball the
// ray meets: at a sample where the field is f, the m metaballs within R + R of it change
// the field by at most m SLOPE_MAX / R per unit length over the next R, so the grid samples
// closer than |f - T| R / (m SLOPE_MAX) are on this sample's side and are skipped (all of
// the next R when m = 0). The first sample across T, its bracket and its bisection are the
// fixed march's: the same hits.
float march_lipschitz(vec3 o, vec3 d, float t0, float t1, bool inside, uint pixel) {
    float T = threshold(), step = P.sun.w, reach = radius();
    float slope = SLOPE_MAX / radius();
    float k0 = ceil(t0 / step);
    float k = 0.0;
    float t = k0 * step;
    n_rays++;
    uint i = 0u;
    for (; i < P.max_steps && k < float(P.max_steps) && t <= t1; ++i) {
        vec3 x = o + d * t;
        vec2 fm = field_reach(x, pixel, reach);
        if ((fm.x >= T) != inside) {
            n_steps += i + 1u;
            return bisect(o, d, max(t - step, 0.0), t, inside, pixel);
        }
        float safe = fm.y > 0.0 ? abs(fm.x - T) / (fm.y * slope) : reach;
        // Samples strictly closer than `safe` (and within `reach`) are skipped.
        k += max(ceil(min(safe, reach) / step - 1e-4), 1.0);
        t = (k0 + k) * step;
    }
    CUT_UNLESS(!(i < P.max_steps && k < float(P.max_steps) && t <= t1))
    n_steps += i;
    return -1.0;
}
#elif MARCH != MARCH_FIXED
#error "MARCH is MARCH_FIXED or MARCH_LIPSCHITZ"
#endif
#elif RAY_LANES == 8 || RAY_LANES == 16 || RAY_LANES == 32
// The crossing between ray parameters a (this side of T) and b (across it), refined by
// P.refine bisection steps; pixel as in `march` (NIL: each sample projects). Each round
// takes BISECT_LEVELS levels at once: lane j evaluates node j + 1 of the round's
// midpoint tree (heap order; a node's midpoint computed down its path exactly as the
// serial steps compute it), and the ballot's bits replay the serial decisions.
float bisect(vec3 o, vec3 d, float a, float b, bool inside, uint pixel) {
    float T = threshold();
    uint lane = ray_lane(), h = lane + 1u, level = uint(findMSB(h));
    uint k = 0u;
    for (; k < P.refine;) {
        uint r = min(BISECT_LEVELS, P.refine - k);
        bool mine = level < r;
        float la = a, lb = b;
        [[unroll]] for (uint l = 0u; l < BISECT_LEVELS; ++l) {
            if (l < level) {
                float m = 0.5 * (la + lb);
                if (((h >> (level - 1u - l)) & 1u) == 0u) lb = m; else la = m;
            }
        }
        uint e0 = n_evals;
        bool across = false;
        if (mine) {
            float m = 0.5 * (la + lb);
            vec3 xm = o + d * m;
            uint pm = pixel == NIL ? project(xm) : pixel;
            if (pm == NIL) pm = ALL;
            across = (field(xm, pm) >= T) != inside;
        }
        uint bits = lanes_ballot(across);
        // The serial steps: node n's decision, then its child (2n: across, b = m).
        uint node = 1u;
        bool on_path = false;
        [[unroll]] for (uint l = 0u; l < BISECT_LEVELS; ++l) {
            if (l < r) {
                on_path = on_path || node == h;
                float m = 0.5 * (a + b);
                bool c = ((bits >> (node - 1u)) & 1u) != 0u;
                if (c) b = m; else a = m;
                node = 2u * node + (c ? 0u : 1u);
            }
        }
        // Terms of midpoints off the serial path are speculation, not the march's count.
        if (mine && !on_path) n_evals = e0;
        k += r;
    }
    CUT_UNLESS(!(k < P.refine))
    n_steps += k;  // the samples the serial bisection takes
    return b;
}

// March [t0, t1] as the serial march does (below RAY_LANES == 1), RAY_LANES samples a
// round: lane j takes grid sample i + j. The first lane that crosses T (or leaves the
// screen, with offscreen_end) ends the march; samples past it are speculation and leave
// the counts as the serial march's.
float march(vec3 o, vec3 d, float t0, float t1, bool inside, uint pixel) {
    float T = threshold(), step = P.sun.w;
    float t = ceil(t0 / step) * step;
    float prev = max(t - step, 0.0);
    uint lane = ray_lane();
    uint i = 0u, skipped = 0u;
    bool skips = skips_empty(pixel, inside);
    n_rays++;
    bool more = true;
    for (; more;) {
        float tj = grid_ahead(t, step, lane);
        bool valid = i + lane < P.max_steps && tj <= t1;
        uint e0 = n_evals, off0 = offscreen_samples;
        bool leaves = false, across = false, empty = false;
        if (valid) {
            vec3 x = o + d * tj;
            uint p = pixel;
            if (pixel == NIL) {
                p = project(x);
                if (p == NIL) {
                    offscreen_samples++;
                    leaves = P.offscreen_end != 0u;
                    p = ALL;
                }
                empty = !leaves && skips && in_empty_cell(x);
            }
            if (!leaves && !empty) across = (field(x, p) >= T) != inside;
        }
        uint passed = lanes_ballot(empty);
        uint f = lanes_first(leaves || across);
        if (f < RAY_LANES) {
            if (lane > f) {
                n_evals = e0;
                offscreen_samples = off0;
            }
            count_samples(i + f + 1u, skipped + bitCount(passed & lanes_below(f)));
            if (lanes_first(across) != f) return -2.0;
            float pf = f == 0u ? prev : grid_ahead(t, step, f - 1u);
            return bisect(o, d, pf, grid_ahead(t, step, f), inside, pixel);
        }
        uint end = lanes_first(!valid);
        if (end < RAY_LANES) {
            count_samples(i + end, skipped + bitCount(passed & lanes_below(end)));
            more = false;
        } else {
            i += RAY_LANES;
            skipped += bitCount(passed);
            prev = grid_ahead(t, step, RAY_LANES - 1u);
            t = grid_ahead(t, step, RAY_LANES);
        }
    }
    CUT_UNLESS(!more)
    return -1.0;
}

#if MARCH == MARCH_LIPSCHITZ
// The Lipschitz march (below RAY_LANES == 1) on RAY_LANES consecutive grid samples a
// round: the first that crosses T is the fixed march's first crossing, and the next round
// starts at the farthest sample a lane's bound proves on this side (each lane's skip
// starts at or before the last sample evaluated, so nothing unproven is skipped). The
// samples counted are those evaluated up to the hit.
float march_lipschitz(vec3 o, vec3 d, float t0, float t1, bool inside, uint pixel) {
    float T = threshold(), step = P.sun.w, reach = radius();
    float slope = SLOPE_MAX / radius();
    float k0 = ceil(t0 / step);
    uint lane = ray_lane();
    float k = 0.0;
    n_rays++;
    uint i = 0u;
    bool more = true;
    for (; more && i < P.max_steps;) {
        float kj = k + float(lane);
        float tj = (k0 + kj) * step;
        bool valid = kj < float(P.max_steps) && tj <= t1;
        uint e0 = n_evals;
        bool across = false;
        float next = kj + 1.0;
        if (valid) {
            vec2 fm = field_reach(o + d * tj, pixel, reach);
            across = (fm.x >= T) != inside;
            float safe = fm.y > 0.0 ? abs(fm.x - T) / (fm.y * slope) : reach;
            next = kj + max(ceil(min(safe, reach) / step - 1e-4), 1.0);
        }
        uint f = lanes_first(across);
        if (f < RAY_LANES) {
            if (lane > f) n_evals = e0;
            n_steps += i + f + 1u;
            float tf = (k0 + k + float(f)) * step;
            return bisect(o, d, max(tf - step, 0.0), tf, inside, pixel);
        }
        uint end = lanes_first(!valid);
        if (end < RAY_LANES) {
            n_steps += i + end;
            more = false;
        } else {
            i += RAY_LANES;
            k = lanes_max(next);
        }
    }
    CUT_UNLESS(!more || !(i < P.max_steps))
    if (more) n_steps += i;
    return -1.0;
}
#elif MARCH != MARCH_FIXED
#error "MARCH is MARCH_FIXED or MARCH_LIPSCHITZ"
#endif
#else
#error "RAY_LANES is 1, 8, 16 or 32"
#endif
#endif
