// The lattice steps inside along one pixel's sorted list: for each run between two
// fragments where the running sum of signs is non-zero (positive for outward meshes; an
// inward or mirrored one counts too, as on the CPU), the steps k with
// lo.z + (k + 1/2) s in [z0, z1). EMIT(k) is called for each.
#include "rays.glsl"
uint range_start(uint p) { return p == 0u ? 0u : offsets[p - 1u]; }

// Steps k with lo.z + (k + 1/2) s >= z (clamped to the lattice).
int first_step(float z) {
    // Clamped as a float first: a huge or NaN depth must not reach the int conversion.
    float k = clamp(ceil((z - pc.lo.z) / pc.lo.w - 0.5), 0.0, float(pc.dims.z));
    return k == k ? int(k) : 0;
}
