// The lattice steps inside along one pixel's sorted list: for each run between two
// fragments where the running sum of signs is positive, the steps k with
// lo.z + (k + 1/2) s in [z0, z1). EMIT(k) is called for each.
#include "rays.glsl"
uint range_start(uint p) { return p == 0u ? 0u : offsets[p - 1u]; }

// Steps k with lo.z + (k + 1/2) s >= z (clamped to the lattice).
int first_step(float z) {
    return clamp(int(ceil((z - pc.lo.z) / pc.lo.w - 0.5)), 0, int(pc.dims.z));
}
