#version 450
// Neighbour lists: every j != i within radius of sorted particle i (indices are sorted
// slots). counts[i] is the true count even when the list (max_neighbors) overflows;
// visited[i] counts the candidates examined.
#include "common/index.glsl"
#include "nb_common.glsl"
#define NB_B_KEYS NBQ_B_NB_KEYS
#define NB_B_START NBQ_B_NB_START
#define NB_B_END NBQ_B_NB_END
#define NB_B_BOX NBQ_B_NB_BOX
#include "neighbors.glsl"
layout(std430, binding = NBQ_B_POS) readonly buffer Pos { vec4 pos[]; };  // sorted positions
layout(std430, binding = NBQ_B_COUNTS) writeonly buffer Counts { uint counts[]; };
layout(std430, binding = NBQ_B_LIST) writeonly buffer List { uint list[]; };
layout(std430, binding = NBQ_B_VISITED) writeonly buffer Visited { uint visited[]; };
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    vec3 p = pos[i].xyz;
    float r2 = pc.radius * pc.radius;
    uint c = 0u, seen = 0u;
    NB_BEGIN(p, pc.radius, j)
        seen++;
        vec3 d = pos[j].xyz - p;
        if (j != i && dot(d, d) <= r2) {
            if (c < pc.max_neighbors) list[i * pc.max_neighbors + c] = j;
            c++;
        }
    NB_END
    counts[i] = c;
    visited[i] = seen;
}
