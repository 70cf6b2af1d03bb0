#version 450
// The state's health after a frame (src/sim/sph/health.rs): particles with a non-finite
// velocity or density, the largest speed^2 and density. Non-negative floats order like
// their bits, so atomicMax on the bits takes the float maximum.
#include "common/index.glsl"
struct Health {
    uint nonfinite;
    uint max_speed2;   // float bits
    uint max_density;  // float bits
    uint pad;
};
layout(std430, binding = HEALTH_B_VEL) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = HEALTH_B_RHO_P) readonly buffer RhoP { vec2 rho_p[]; };
layout(std430, binding = HEALTH_B_OUT) buffer Out { Health h; };
layout(push_constant) uniform Push { uint n; } pc;
void main() {
    uint i = global_id();
    if (i >= pc.n) return;
    vec3 v = vel[i].xyz;
    float r = rho_p[i].x;
    if (any(isnan(v)) || any(isinf(v)) || isnan(r) || isinf(r)) {
        atomicAdd(h.nonfinite, 1u);
        return;
    }
    atomicMax(h.max_speed2, floatBitsToUint(dot(v, v)));
    atomicMax(h.max_density, floatBitsToUint(max(r, 0.0)));
}
