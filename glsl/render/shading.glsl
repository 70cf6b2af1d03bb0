// Shading shared by every surface (the metaballs' march.comp, the other surfaces'
// shade.comp): the sky, the dielectric Fresnel term, Phong, the container's walls and the
// opaque layer. The includer declares P (RenderParams), sky[] and opaque[].
#ifndef RENDER_SHADING_GLSL
#define RENDER_SHADING_GLSL
vec3 unpack_rgb(uint v) { return unpackUnorm4x8(v).rgb; }

// The checks' parity at p (one check per unit), box-filtered over a square of side w
// (Quilez's analytic integral of the checker): 0 or 1 when w -> 0, 0.5 when w covers many.
float filtered_check(vec2 p, float w) {
    w = max(w, 1e-4);
    vec2 i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
    return 0.5 - 0.5 * i.x * i.y;
}

// A ray cone (Akenine-Moller et al. 2019, "Texture level of detail strategies for
// real-time ray tracing"): x its width at the ray's origin, y its spread angle. Carried
// along a path: the width grows by spread x distance; at a surface curved no tighter than
// radius rc (the metaball radius) the normal turns by up to width / rc across the cone,
// which a reflection doubles in the spread and a refraction passes about once.
vec2 cone_at(vec2 c, float t) { return vec2(c.x + c.y * t, c.y); }
vec2 cone_bent(vec2 c, float rc, float turns) { return vec2(c.x, c.y + turns * c.x / rc); }

// Procedural sky (gradient, sun, checkered ground) or an equirectangular image. The ground
// is filtered over the ray cone's footprint on it: the spread through the plane one
// metre down (d(tan)/d(angle) = 1 + tan^2) plus the cone's width seen at the ray's slope.
vec3 sky_color(vec3 d, vec2 cone) {
    if (P.sky_w > 0u) {
        // Bilinear lookup, wrapping in longitude and clamping in latitude.
        float u = atan(d.z, d.x) / (2.0 * 3.14159265) + 0.5;
        float v = acos(clamp(d.y, -1.0, 1.0)) / 3.14159265;
        vec2 st = vec2(u * float(P.sky_w) - 0.5, v * float(P.sky_h) - 0.5);
        vec2 fl = floor(st);
        vec2 f = st - fl;
        int w = int(P.sky_w), h = int(P.sky_h);
        int x0 = int(fl.x);
        x0 = x0 < 0 ? x0 + w : (x0 >= w ? x0 - w : x0);
        int x1 = x0 + 1 >= w ? 0 : x0 + 1;
        int y0 = clamp(int(fl.y), 0, h - 1), y1 = clamp(int(fl.y) + 1, 0, h - 1);
        vec3 c00 = unpack_rgb(sky[y0 * w + x0]), c10 = unpack_rgb(sky[y0 * w + x1]);
        vec3 c01 = unpack_rgb(sky[y1 * w + x0]), c11 = unpack_rgb(sky[y1 * w + x1]);
        return pow(mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y), vec3(2.2));
    }
    if (d.y < 0.0) {
        float down = max(-d.y, 1e-3);
        vec2 g = d.xz / down;
        float foot = cone.y * (1.0 + dot(g, g)) + cone.x / down;
        float check = filtered_check(g * 2.0, foot * 2.0);
        return mix(vec3(0.25, 0.23, 0.2), vec3(0.45, 0.42, 0.38), check) * (0.6 + 0.4 * min(-d.y * 4.0, 1.0));
    }
    vec3 c = mix(vec3(0.75, 0.82, 0.9), vec3(0.25, 0.45, 0.8), pow(d.y, 0.6));
    float s = max(dot(d, P.sun.xyz), 0.0);
    return c + vec3(1.0, 0.9, 0.7) * (pow(s, 400.0) * 8.0 + pow(s, 8.0) * 0.2);
}

// The exact unpolarised reflectance of a dielectric interface, from index n1 into n2 at
// incidence cosine cos_i (Hecht, Optics, 4.6): 1 past the critical angle. (Schlick's
// approximation taken with cos_i inside the denser medium misses the rise towards total
// internal reflection.)
float fresnel_dielectric(float cos_i, float n1, float n2) {
    float sin_t = n1 / n2 * sqrt(max(1.0 - cos_i * cos_i, 0.0));
    if (sin_t >= 1.0) return 1.0;
    float cos_t = sqrt(1.0 - sin_t * sin_t);
    float rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    float rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

vec3 phong(vec3 n, vec3 v) {
    vec3 l = P.sun.xyz;
    float diff = max(dot(n, l), 0.0);
    vec3 h = normalize(l + v);
    float spec = pow(max(dot(n, h), 0.0), 64.0);
    return P.base.rgb * (0.15 + 0.85 * diff) + vec3(0.6) * spec;
}

// The container as thin glass walls with dark edges, over what the primary ray saw up to
// t_max (the fluid's first hit, or infinity): each wall face in front tints, its edges draw.
vec3 with_tank(vec3 color, vec3 o, vec3 d, float t_max) {
    if (P.tank_min.w == 0.0) return color;
    vec3 lo = P.tank_min.xyz, hi = P.tank_max.xyz;
    vec3 inv = 1.0 / d;
    vec3 t0 = (lo - o) * inv, t1 = (hi - o) * inv;
    vec3 tn = min(t0, t1), tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), tn.z), leave = min(min(tf.x, tf.y), tf.z);
    if (enter > leave || leave <= 0.0) return color;
    float faces[2] = float[2](enter, leave);
    for (int k = 0; k < 2; ++k) {
        float t = faces[k];
        if (t <= 0.0 || t > t_max) continue;
        vec3 p = o + d * t;
        // Near an edge: two coordinates at their bounds (width grows with distance).
        float w = 0.0025 * t;
        vec3 near_lo = step(abs(p - lo), vec3(w)), near_hi = step(abs(p - hi), vec3(w));
        float on = dot(max(near_lo, near_hi), vec3(1.0));
        color = on >= 2.0 ? mix(color, vec3(0.02, 0.03, 0.05), 0.85)
                          : mix(color, vec3(0.75, 0.85, 0.95), 0.08);
    }
    return color;
}

// Distance along the primary ray to the opaque layer (a character's mesh), or 1e30.
float opaque_t(uint id, vec2 ndc, vec3 o, vec3 d) {
    if (P.opaque == 0u) return 1e30;
    float z = uintBitsToFloat(opaque[P.width * P.height + id]);
    if (z >= 1.0) return 1e30;
    vec4 w = P.inv_view_proj * vec4(ndc, z, 1.0);
    return dot(w.xyz / w.w - o, d);
}
#endif
