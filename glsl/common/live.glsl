// The GPU-side live particle count. Mirrors LiveCount in src/sim/sph/store.rs.
#ifndef COMMON_LIVE_GLSL
#define COMMON_LIVE_GLSL
struct LiveCount {
    uint n;
    uint capacity;
    uint local_size;
    uint pad;
    uint groups[3];  // VkDispatchIndirectCommand for local_size invocations per group
    uint pad2;
};
#endif
