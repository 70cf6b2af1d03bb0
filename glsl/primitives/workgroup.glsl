// Workgroup-wide exclusive scan of one u32 per invocation.
// SUBGROUP=1: subgroup arithmetic plus one shared slot per subgroup;
// SUBGROUP=0: a shared-memory Hillis-Steele scan (devices without subgroup arithmetic).
// Both assume invocations are numbered in subgroup order (gl_LocalInvocationIndex).
#ifndef PRIMITIVES_WORKGROUP_GLSL
#define PRIMITIVES_WORKGROUP_GLSL
#ifndef SUBGROUP
#define SUBGROUP 0
#endif
#if SUBGROUP
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
shared uint wg_sums[gl_WorkGroupSize.x];
shared uint wg_total;

// The first subgroup scans the subgroup totals in chunks of its own width, so each
// invocation does O(1) work whatever the subgroup size. Call at most once per invocation.
uint wg_exclusive_scan(uint v, out uint total) {
    uint incl = subgroupInclusiveAdd(v);
    uint last = subgroupBallotFindMSB(subgroupBallot(true));
    if (gl_SubgroupInvocationID == last) wg_sums[gl_SubgroupID] = incl;
    barrier();
    if (gl_SubgroupID == 0u) {
        uint carry = 0u;
        for (uint base = 0u; base < gl_NumSubgroups; base += gl_SubgroupSize) {
            uint i = base + gl_SubgroupInvocationID;
            uint x = i < gl_NumSubgroups ? wg_sums[i] : 0u;
            uint ex = subgroupExclusiveAdd(x);
            if (i < gl_NumSubgroups) wg_sums[i] = carry + ex;
            carry += subgroupAdd(x);
        }
        if (subgroupElect()) wg_total = carry;
    }
    barrier();
    total = wg_total;
    return wg_sums[gl_SubgroupID] + incl - v;
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

#endif
#endif
