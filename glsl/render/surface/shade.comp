#version 450
// Lights the G-buffer of screen-space fluid or marching cubes with the metaballs'
// materials (render/shading.glsl), one hit per pixel: Phong; the metals' Schlick term
// over the reflected sky; glass and tinted the exact dielectric Fresnel term splitting
// reflected sky and what lies behind along the refracted ray, tinted by Beer-Lambert over
// the thickness. The opaque layer shows where it is nearer than the fluid.
#include "common/index.glsl"
#include "common.glsl"
#include "render/shading.glsl"

void main() {
    uint id = global_id();
    if (id >= pixel_count()) return;
    uvec2 pix = uvec2(id % P.width, id / P.width);
    vec2 ndc = (vec2(pix) + 0.5) / vec2(P.width, P.height) * 2.0 - 1.0;
    vec3 o = P.eye.xyz, d = primary_dir(vec2(pix));
    // The pixel's ray cone (render/shading.glsl), then at the hit, bent once or twice.
    vec2 cone = vec2(0.0, length(primary_dir(vec2(pix) + vec2(1.0, 0.0)) - d));
    vec4 g = gbuf[2u * id];
    float t_opaque = opaque_t(id, ndc, o, d);
    float t = g.x > 0.0 ? g.x / depth_rate(d) : -1.0;
    if (t >= t_opaque) t = -1.0;
    vec3 opaque_rgb = t_opaque < 1e30 ? pow(unpackUnorm4x8(opaque[id]).rgb, vec3(2.2)) : vec3(0.0);
    vec3 color;
    if (t < 0.0) {
        color = t_opaque < 1e30 ? opaque_rgb : sky_color(d, cone);
    } else {
        vec2 hit = cone_at(cone, t);
        vec3 n = normalize(g.yzw);
        float cos_i = clamp(-dot(d, n), 0.0, 1.0);
        vec3 rd = reflect(d, n);
#if MATERIAL == MATERIAL_PHONG
        color = phong(n, -d);
#elif MATERIAL == MATERIAL_METAL
        vec3 F = P.f0.rgb + (1.0 - P.f0.rgb) * pow(1.0 - cos_i, 5.0);
        color = F * sky_color(rd, cone_bent(hit, P.eye.w, 2.0));
#elif MATERIAL == MATERIAL_GLASS || MATERIAL == MATERIAL_TINTED
        float F = fresnel_dielectric(cos_i, 1.0, P.absorb.w);
        vec3 td = refract(d, n, 1.0 / P.absorb.w);
        vec3 behind = t_opaque < 1e30 ? opaque_rgb : sky_color(normalize(td), cone_bent(hit, P.eye.w, 1.0));
#if MATERIAL == MATERIAL_TINTED
        behind *= exp(-P.absorb.rgb * gbuf[2u * id + 1u].x);  // Beer-Lambert
#endif
        color = F * sky_color(rd, cone_bent(hit, P.eye.w, 2.0)) + (1.0 - F) * behind;
#else
#error "MATERIAL names no material"
#endif
    }
    color = with_tank(color, o, d, min(t >= 0.0 ? t : 1e30, t_opaque));
    color = pow(clamp(color, 0.0, 1.0), vec3(1.0 / 2.2));
    pixels[id] = packUnorm4x8(vec4(color, 1.0));
    if (P.opaque != 0u) {
        // Layers drawn over the picture (blended particles) are depth-tested against it.
        float z = uintBitsToFloat(opaque[pixel_count() + id]);
        if (t >= 0.0) {
            vec4 c = P.view_proj * vec4(o + d * t, 1.0);
            z = min(z, c.z / c.w);
        }
        scene_depth[id] = z;
    }
}
