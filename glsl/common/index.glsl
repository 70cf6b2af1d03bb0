// Linear invocation index for dispatches split over y (more than 65535 groups in x);
// see ComputePipeline::dispatch_groups.
#ifndef COMMON_INDEX_GLSL
#define COMMON_INDEX_GLSL
uint global_id() {
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    return group * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
}
uint group_id() { return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x; }
#endif
