// Compute passes over 8 x 8 pixel blocks (pixel_lists.comp, march.comp with LIST_TILES).
// The includer includes common.glsl first.
#ifndef METABALL_BLOCKS_GLSL
#define METABALL_BLOCKS_GLSL
// Passes over 8 x 8 pixel blocks (one workgroup of 64 each; a tile holds whole blocks):
// this invocation's pixel, and the first pixel of block g (of this workgroup's block).
uvec2 block_origin_of(uint g) {
    uint per_row = (P.width + 7u) / 8u;
    return uvec2(g % per_row, g / per_row) * 8u;
}
uvec2 block_origin() { return block_origin_of(gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x); }
uvec2 block_pixel() {
    uint l = gl_LocalInvocationIndex;
    return block_origin() + uvec2(l % 8u, l / 8u);
}

#endif
