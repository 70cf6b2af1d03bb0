#version 450
// Skinning (src/sim/character/skin.rs): every vertex's position and normal from its joint
// influences. SKIN_METHOD 0: linear blend of the joint matrices, normals by the blend's
// cofactor matrix. 1: dual quaternions (Kavan et al. 2008) with the antipodality fix
// against the heaviest influence; the polar stretch S blended linearly first (§4).
// SKIN_SETS: 1 (4 influences per vertex) or 2 (8). The CPU reference is cpu.rs.
#include "common/index.glsl"
struct Joint {
    mat4 m;
    vec4 real;
    vec4 dual;
    vec4 s[3];
};
layout(std430, binding = SKIN_B_JOINTS) readonly buffer Joints { Joint joints[]; };
layout(std430, binding = SKIN_B_REST_POS) readonly buffer RestPos { vec4 rest_pos[]; };
layout(std430, binding = SKIN_B_REST_NRM) readonly buffer RestNrm { vec4 rest_nrm[]; };
// Four u16 joint indices per set, two per uint.
layout(std430, binding = SKIN_B_JOINT_IDS) readonly buffer JointIds { uvec2 joint_ids[]; };
layout(std430, binding = SKIN_B_WEIGHTS) readonly buffer Weights { vec4 weights[]; };
layout(std430, binding = SKIN_B_OUT_POS) writeonly buffer OutPos { vec4 out_pos[]; };
layout(std430, binding = SKIN_B_OUT_NRM) writeonly buffer OutNrm { vec4 out_nrm[]; };
// Morph targets, added before skinning: vertex v's offsets are entries
// morph_start[v] .. morph_start[v + 1], each a position offset (its target's index in w,
// a float holding an integer) and a normal offset; every vertex's range is empty without
// targets.
layout(std430, binding = SKIN_B_MORPH_START) readonly buffer MorphStart { uint morph_start[]; };
layout(std430, binding = SKIN_B_MORPH_DELTAS) readonly buffer MorphDeltas { vec4 morph_deltas[]; };
layout(std430, binding = SKIN_B_MORPH_WEIGHTS) readonly buffer MorphWeights { float morph_weights[]; };
layout(push_constant) uniform Push { uint n; uint morphs; } pc;

mat3 cofactor(mat3 a) { return mat3(cross(a[1], a[2]), cross(a[2], a[0]), cross(a[0], a[1])); }
vec3 rotate(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }
uint joint_of(uvec2 ids, uint k) { return ((k < 2u ? ids.x : ids.y) >> (16u * (k & 1u))) & 0xffffu; }

void main() {
    uint v = global_id();
    if (v >= pc.n) return;
    vec3 p = rest_pos[v].xyz;
    vec3 n = rest_nrm[v].xyz;
    // (Uniform: a mesh without targets reads no range.)
    if (pc.morphs != 0u) {
        for (uint e = morph_start[v]; e < morph_start[v + 1u]; ++e) {
            vec4 dp = morph_deltas[2u * e];
            float w = morph_weights[uint(dp.w)];
            p += w * dp.xyz;
            n += w * morph_deltas[2u * e + 1u].xyz;
        }
    }
#if SKIN_METHOD == 0
    mat3 a = mat3(0.0);
    vec3 t = vec3(0.0);
    for (uint s = 0u; s < SKIN_SETS; ++s) {
        uvec2 ids = joint_ids[v * SKIN_SETS + s];
        vec4 w = weights[v * SKIN_SETS + s];
        for (uint k = 0u; k < 4u; ++k) {
            Joint j = joints[joint_of(ids, k)];
            a += mat3(j.m) * w[k];
            t += j.m[3].xyz * w[k];
        }
    }
    out_pos[v] = vec4(a * p + t, rest_pos[v].w);
    vec3 nn = cofactor(a) * n;
#elif SKIN_METHOD == 1
    vec4 q0 = joints[joint_of(joint_ids[v * SKIN_SETS], 0u)].real;
    vec4 r = vec4(0.0), d = vec4(0.0);
    mat3 st = mat3(0.0);
    for (uint s = 0u; s < SKIN_SETS; ++s) {
        uvec2 ids = joint_ids[v * SKIN_SETS + s];
        vec4 w = weights[v * SKIN_SETS + s];
        for (uint k = 0u; k < 4u; ++k) {
            Joint j = joints[joint_of(ids, k)];
            float sw = dot(j.real, q0) < 0.0 ? -w[k] : w[k];
            r += j.real * sw;
            d += j.dual * sw;
            st += mat3(j.s[0].xyz, j.s[1].xyz, j.s[2].xyz) * w[k];
        }
    }
    float len = length(r);
    r /= len;
    d /= len;
    vec3 t = 2.0 * (r.w * d.xyz - d.w * r.xyz + cross(r.xyz, d.xyz));
    out_pos[v] = vec4(rotate(r, st * p) + t, rest_pos[v].w);
    vec3 nn = rotate(r, cofactor(st) * n);
#else
#error "SKIN_METHOD is 0 (linear blend) or 1 (dual quaternion)"
#endif
    float l = length(nn);
    out_nrm[v] = vec4(l > 0.0 ? nn / l : vec3(0.0), 0.0);
}
