// Every compute shader includes this first: it declares the workgroup size as
// specialization constant 0 (set by ComputeDesc::local_size) before any use of
// gl_WorkGroupSize, and linearises dispatches split over y (more than 65535 groups in x;
// see ComputePipeline::dispatch_groups).
#ifndef COMMON_INDEX_GLSL
#define COMMON_INDEX_GLSL
layout(local_size_x_id = 0) in;
uint group_id() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }
uint global_id() { return group_id() * gl_WorkGroupSize.x + gl_LocalInvocationID.x; }
#endif
