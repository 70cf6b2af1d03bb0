// The per-frame push constants of every particle-system compute pass (StepPush in
// src/sim/psys/gpu.rs).
#ifndef PSYS_PUSH_GLSL
#define PSYS_PUSH_GLSL
layout(push_constant) uniform Push {
    mat4 view_proj;  // out-of-view death
    vec4 source;     // xyz the emitter's centre this frame, w time (s)
    uint births;     // emit: births this frame
    uint seed;       // frame seed
    uint cur;        // the alive list this frame reads (0 or 1)
    uint head;       // closed: the ring's next slot
    float dt;
    uint capacity;
    uint mode;       // args: 0 before the update, 1 after, 2 zero the draw count,
                     // 3 the spawn's dispatch | keys: 0 network keys, 1 counting-sort
                     // cells | emit: 0 the emitter's births, else spawn on events of
                     // this kind (source: x count mean, y variance, z inherit; births:
                     // 1 children's velocity along the contact normal)
    uint cells;      // keys: counting-sort cells
    float near;      // keys: the depth range the counting sort quantises (log scale)
    float far;
    uint capsules;   // the scene character's capsules (0: none)
    uint triangles;  // its triangles
} pc;
#endif
