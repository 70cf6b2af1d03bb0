#version 450
// Per-pixel metaball lists from the billboards. PASS 0: S-buffer count; PASS 1: S-buffer
// fill (each fragment takes the next slot of its pixel's range, advancing the scanned
// start to the range's end); PASS 2: A-buffer (node from the atomic counter, pushed at the
// pixel's head). Entries past the capacity are counted as overflow, never written.
#include "common.glsl"
#ifndef PASS
#define PASS 0
#endif
layout(location = 0) flat in uint v_id;
void main() {
    uint p = pixel_index(uvec2(gl_FragCoord.xy));
#if PASS == 0
    atomicAdd(offsets[p], 1u);
#elif PASS == 1
    uint slot = atomicAdd(offsets[p], 1u);
    if (slot < P.list_capacity) list[slot] = v_id; else atomicAdd(stats.overflow, 1u);
#elif PASS == 2
    uint node = atomicAdd(stats.abuffer_nodes, 1u);
    if (node < P.list_capacity) nodes[node] = uvec2(v_id, atomicExchange(heads[p], node));
    else atomicAdd(stats.overflow, 1u);
#else
#error "PASS is 0 (count), 1 (fill) or 2 (A-buffer)"
#endif
}
