// Shared parts of the sorting networks. Keys and values are sorted in place; every
// comparator puts the smaller key at the lower index, and indices >= n act as +infinity
// (such a comparator never swaps), so any n sorts without padding.
#ifndef PRIMITIVES_SORT_COMMON_GLSL
#define PRIMITIVES_SORT_COMMON_GLSL
layout(constant_id = 1) const uint BLOCK = 2048;  // elements per shared-memory tile
layout(std430, binding = SORT_B_KEYS) buffer Keys { uint keys[]; };  // keys
layout(std430, binding = SORT_B_VALS) buffer Vals { uint vals[]; };  // values
layout(push_constant) uniform Push { uint n; uint p; uint k; uint mode; } pc;
const uint MODE_LOCAL_SORT = 0u, MODE_GLOBAL = 1u, MODE_LOCAL_MERGE = 2u;

shared uint t_keys[BLOCK];
shared uint t_vals[BLOCK];

void tile_load(uint base) {
    for (uint x = gl_LocalInvocationIndex; x < BLOCK; x += gl_WorkGroupSize.x) {
        if (base + x < pc.n) { t_keys[x] = keys[base + x]; t_vals[x] = vals[base + x]; }
    }
    barrier();
}

void tile_store(uint base) {
    barrier();
    for (uint x = gl_LocalInvocationIndex; x < BLOCK; x += gl_WorkGroupSize.x) {
        if (base + x < pc.n) { keys[base + x] = t_keys[x]; vals[base + x] = t_vals[x]; }
    }
}

void tile_cmpswap(uint a, uint b) {  // a < b, both inside the tile and < n
    uint ka = t_keys[a], kb = t_keys[b];
    if (ka > kb) {
        t_keys[a] = kb; t_keys[b] = ka;
        uint v = t_vals[a]; t_vals[a] = t_vals[b]; t_vals[b] = v;
    }
}

void global_cmpswap(uint a, uint b) {
    uint ka = keys[a], kb = keys[b];
    if (ka > kb) {
        keys[a] = kb; keys[b] = ka;
        uint v = vals[a]; vals[a] = vals[b]; vals[b] = v;
    }
}
#endif
