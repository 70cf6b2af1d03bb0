#version 450
// Marching cubes into the G-buffer, in two passes over the same triangles. PASS 0: the
// nearest view depth (atomicMin on the float bits) and the thickness, the back faces'
// depths minus the front faces' (the closed surface's length inside along the view axis).
// PASS 1: the fragment at the nearest depth writes its normal and the thickness along
// its ray.
#include "common.glsl"
layout(location = 0) in vec3 world;
layout(location = 1) in vec3 normal;
layout(location = 2) flat in float facing;

void main() {
    uvec2 pix = uvec2(gl_FragCoord.xy);
    uint p = pix.y * P.width + pix.x;
    float z = max(view_depth(world), 0.0);
#if !defined(PASS)
#error "PASS is 0 (depth and thickness) or 1 (normals)"
#elif PASS == 0
    atomicMin(zbits[p], floatBitsToUint(z));
    atomicAdd(thick[p], int(round(-facing * z * THICK_SCALE)));
#elif PASS == 1
    if (floatBitsToUint(z) != zbits[p]) return;
    float l = length(normal);
    vec3 d = primary_dir(vec2(pix));
    gbuf[2u * p] = vec4(z, l > 0.0 ? normal / l : -d);
    gbuf[2u * p + 1u] = vec4(max(float(thick[p]) / THICK_SCALE, 0.0) / depth_rate(d), 0.0, 0.0, 0.0);
#else
#error "PASS is 0 (depth and thickness) or 1 (normals)"
#endif
}
