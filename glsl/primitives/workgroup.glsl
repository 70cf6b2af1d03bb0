// Workgroup-wide reduce and exclusive scan of one u32 per invocation.
// SUBGROUP=1: subgroup arithmetic plus one shared slot per subgroup;
// SUBGROUP=0: a shared-memory Hillis-Steele scan (devices without subgroup arithmetic).
// Both assume invocations are numbered in subgroup order (gl_LocalInvocationIndex).
#ifndef PRIMITIVES_WORKGROUP_GLSL
#define PRIMITIVES_WORKGROUP_GLSL
#if SUBGROUP
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
shared uint wg_sums[gl_WorkGroupSize.x];

uint wg_exclusive_scan(uint v, out uint total) {
    uint incl = subgroupInclusiveAdd(v);
    uint sg_total = subgroupAdd(v);
    if (subgroupElect()) wg_sums[gl_SubgroupID] = sg_total;
    barrier();
    uint before = 0;
    total = 0;
    for (uint s = 0; s < gl_NumSubgroups; ++s) {
        uint t = wg_sums[s];
        before += s < gl_SubgroupID ? t : 0u;
        total += t;
    }
    barrier();
    return before + incl - v;
}

uint wg_reduce(uint v) {
    uint total;
    wg_exclusive_scan(v, total);
    return total;
}
#else
shared uint wg_sums[2 * gl_WorkGroupSize.x];

uint wg_exclusive_scan(uint v, out uint total) {
    uint lid = gl_LocalInvocationIndex;
    uint n = gl_WorkGroupSize.x;
    uint src = 0;
    wg_sums[lid] = v;
    barrier();
    for (uint off = 1; off < n; off <<= 1) {
        uint x = wg_sums[src * n + lid];
        if (lid >= off) x += wg_sums[src * n + lid - off];
        src ^= 1u;
        wg_sums[src * n + lid] = x;
        barrier();
    }
    uint incl = wg_sums[src * n + lid];
    total = wg_sums[src * n + n - 1];
    barrier();
    return incl - v;
}

uint wg_reduce(uint v) {
    uint total;
    wg_exclusive_scan(v, total);
    return total;
}
#endif
#endif
