#version 450
// Sorted S-buffer: every metaball's view depth, the key of the per-pixel sort and of the
// march's depth window.
#include "common/index.glsl"
#include "common.glsl"
void main() {
    uint i = global_id();
    if (i < P.n) depths[i] = view_depth(centers[i].xyz);
}
