// RenderToUV (seed 002): the skinned mesh rasterised into its UV atlas, each covered
// texel holding the world position of the surface point it maps to and its layout
// triangle. Bindings: UvIo in src/sim/emission/uv.rs; Push mirrors UvPush there.
#ifndef EMISSION_UV_GLSL
#define EMISSION_UV_GLSL
layout(push_constant) uniform Push {
    vec4 atlas;   // xy: UV scale, zw: offset (the drawn part's place in the atlas)
    uvec4 size;   // x, y: texels per row and column, z: texels, w: 1 to claim texel owners
} pc;
layout(std430, binding = UV_B_VERTS) readonly buffer Verts { vec4 verts[]; };  // skinned
layout(std430, binding = UV_B_UVS) readonly buffer Uvs { vec2 uvs[]; };        // per corner
layout(std430, binding = UV_B_SRC) readonly buffer Src { uint src[]; };        // corner -> vertex
// Per texel: xyz world position, w = layout triangle + 1 (0: not covered).
layout(std430, binding = UV_B_POS) buffer Pos { vec4 pos[]; };
// Per texel (+1): 1 where covered, then (scanned) its index among the covered ones.
layout(std430, binding = UV_B_FLAGS) buffer Flags { uint flags[]; };
layout(std430, binding = UV_B_VALID) buffer Valid { uint valid[]; };  // covered texels
layout(std430, binding = UV_B_OWNER) buffer Owner { uint owner[]; };  // per texel: its triangle
#endif
