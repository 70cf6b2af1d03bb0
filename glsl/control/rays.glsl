// Rays placement (seed 000, 3.2): the skinned mesh rendered orthographically along +z on
// a pixel grid at the control spacing; every fragment's (z, sign) stored in per-pixel
// lists (S-buffer: count, scan, fill), each list sorted by z, and control particles put
// at the lattice steps z = lo.z + (k + 1/2) s where the running sum of signs (entries +1,
// exits -1) is non-zero, so overlapping closed parts give their union. Bindings: RaysIo
// in src/sim/control/rays.rs; RaysPush mirrors RaysGpuPush there.
#ifndef CONTROL_RAYS_GLSL
#define CONTROL_RAYS_GLSL
layout(push_constant) uniform Push {
    vec4 lo;          // xyz pixel grid and lattice origin, w = spacing s
    uvec4 dims;       // x, y pixels, z lattice steps, w = fragment capacity
    uint capacity;    // control particles that fit
    uint triangles;
    uint pixels;      // dims.x * dims.y
    uint pad;
} pc;
layout(std430, binding = RAY_B_VERTS) readonly buffer Verts { vec4 verts[]; };
layout(std430, binding = RAY_B_INDICES) readonly buffer Indices { uint indices[]; };
// Per pixel (+1): fragment counts, then starts (scan), then ends (after the fill).
layout(std430, binding = RAY_B_OFFSETS) buffer Offsets { uint offsets[]; };
layout(std430, binding = RAY_B_FRAGS) buffer Frags { vec2 frags[]; };  // z, sign
// Per pixel (+1): control particles, then their starts (scan).
layout(std430, binding = RAY_B_EMIT) buffer Emit { uint emit[]; };
layout(std430, binding = RAY_B_OUT) buffer Out { vec4 outp[]; };
// x: fragments, y: control particles (totals copied from the scans), zw unused.
layout(std430, binding = RAY_B_STATS) buffer Stats { uvec4 stats; };
#endif
