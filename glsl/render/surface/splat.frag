#version 450
// Screen-space fluid (van der Laan, Green & Sainz 2009), depth splats: each pixel's ray is
// intersected with the particle's sphere; the nearest front depth wins (atomicMin on the
// float bits) and the chords add up into the thickness, scaled by the particle's volume
// over its sphere's so the thickness integrates to the fluid's volume.
#include "common.glsl"
layout(location = 0) flat in uint v_id;

void main() {
    uvec2 pix = uvec2(gl_FragCoord.xy);
    uint p = pix.y * P.width + pix.x;
    vec3 o = P.eye.xyz, d = primary_dir(vec2(pix));
    float r = pc.fluid.w;
    vec3 oc = o - centers[v_id].xyz;
    float b = dot(oc, d), disc = b * b - (dot(oc, oc) - r * r);
    if (disc <= 0.0) return;
    float s = sqrt(disc);
    float t0 = max(-b - s, 0.0), t1 = -b + s;
    if (t1 <= t0) return;
    float z = max(view_depth(o + d * t0), 0.0);
    atomicMin(zbits[p], floatBitsToUint(z));
    float share = pc.fluid.y / (4.0 / 3.0 * 3.14159265 * r * r * r);
    atomicAdd(thick[p], int((t1 - t0) * share * THICK_SCALE + 0.5));
}
