#version 450
// Rays placement. PASS 0: count each pixel's fragments; PASS 1: store (z, sign) at the
// next slot of the pixel's scanned range (the start advances to the range's end).
// Entries past the capacity are never written; the host compares the total with it.
#include "rays.glsl"
#ifndef PASS
#define PASS 0
#endif
layout(location = 0) in float v_z;
layout(location = 1) flat in float v_sign;
void main() {
    uvec2 q = uvec2(gl_FragCoord.xy);
    uint p = q.y * pc.dims.x + q.x;
#if PASS == 0
    atomicAdd(offsets[p], 1u);
#elif PASS == 1
    uint slot = atomicAdd(offsets[p], 1u);
    if (slot < pc.dims.w) frags[slot] = vec2(v_z, v_sign);
#else
#error "PASS is 0 (count) or 1 (fill)"
#endif
}
