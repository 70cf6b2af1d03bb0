// Scan data views. The same buffer range is bound twice, as uvec4[] (128-bit accesses
// while a run of elements is fully in range) and as uint[] (the array's tail).
#ifndef PRIMITIVES_SCAN_IO_GLSL
#define PRIMITIVES_SCAN_IO_GLSL
// Defaults; src/gpu/primitives/scan.rs defines both (IPT elements per invocation of the top
// level, CHUNK per invocation of a level pass; multiples of 4).
#ifndef IPT
#define IPT 16u
#endif
#ifndef CHUNK
#define CHUNK 64u
#endif
layout(push_constant) uniform Push { uint n; uint base; uint flags; } pc;
const uint INCLUSIVE = 1u, HAS_OFFSETS = 2u;
layout(std430, binding = SCAN_B_IN4) readonly buffer In4 { uvec4 in4[]; };  // input as uvec4
layout(std430, binding = SCAN_B_IN1) readonly buffer In1 { uint in1[]; };  // input as uint
layout(std430, binding = SCAN_B_OUT4) writeonly buffer Out4 { uvec4 out4[]; };  // output as uvec4
layout(std430, binding = SCAN_B_OUT1) writeonly buffer Out1 { uint out1[]; };  // output as uint
layout(std430, binding = SCAN_B_SUMS) coherent buffer Sums { uint sums[]; };  // chunk sums / offsets

// Sum of elements [first, first + count) (count a multiple of 4).
uint run_sum(uint first, uint count) {
    uint s = 0u;
    if (first + count <= pc.n) {
        for (uint k = 0u; k < count / 4u; ++k) {
            uvec4 q = in4[first / 4u + k];
            s += (q.x + q.y) + (q.z + q.w);
        }
    } else {
        for (uint k = 0u; k < count; ++k) s += first + k < pc.n ? in1[first + k] : 0u;
    }
    return s;
}

// Write the scan of elements [first, first + count) starting from pre; returns the carry.
uint run_scan(uint first, uint count, uint pre) {
    bool inclusive = (pc.flags & INCLUSIVE) != 0u;
    if (first + count <= pc.n) {
        for (uint k = 0u; k < count / 4u; ++k) {
            uvec4 q = in4[first / 4u + k];
            uvec4 e = uvec4(pre, pre + q.x, pre + q.x + q.y, pre + q.x + q.y + q.z);
            pre = e.w + q.w;
            out4[first / 4u + k] = inclusive ? e + q : e;
        }
    } else {
        for (uint k = 0u; k < count; ++k) {
            if (first + k < pc.n) {
                uint x = in1[first + k];
                out1[first + k] = inclusive ? pre + x : pre;
                pre += x;
            }
        }
    }
    return pre;
}
#endif
