#version 450
// Sort keys of the drawn particles by view depth, back to front: network sorts get the
// depth's float bits reversed, the counting sort a cell on a log scale between near and
// far (relative resolution ln(far / near) / cells). Entries past the alive particles get
// the largest key and NO_SLOT, so they sort last. Closed form: every slot is tested
// (age within its life) and the drawn ones counted into the draw's vertex count.
#include "common/index.glsl"
#include "state.glsl"
#include "closed.glsl"
void main() {
    uint i = global_id();
    if (i >= pc.capacity) return;
    uint slot = NO_SLOT;
    vec3 p = vec3(0.0);
    if (sp.counts2.y == I_CLOSED) {
        vec4 P = pos[i], V = vel[i];
        float age = pc.source.w - P.w;
        if (P.w >= 0.0 && age >= 0.0 && age < V.w) {
            slot = i;
            p = closed_pos(P.xyz, V.xyz, sp.gravity.xyz, age);
            atomicAdd(c.draw_args[0], c.verts);
        }
    } else if (i < c.alive[1u - pc.cur]) {
        slot = alive[(1u - pc.cur) * pc.capacity + i];
        p = pos[slot].xyz;
    }
    float d = (pc.view_proj * vec4(p, 1.0)).w;  // view depth (perspective)
    uint key;
    if (pc.mode == 0u) {
        key = slot == NO_SLOT ? 0xFFFFFFFFu : 0xFFFFFFFEu - floatBitsToUint(max(d, 0.0));
    } else {
        float q = log(clamp(d, pc.near, pc.far) / pc.near) / log(pc.far / pc.near);
        key = slot == NO_SLOT ? pc.cells - 1u : uint((1.0 - q) * float(pc.cells - 2u) + 0.5);
    }
    keys[i] = key;
    vals[i] = slot;
}
