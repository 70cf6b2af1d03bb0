// SPH after Müller et al. 2003 / Kelager 2006: parameters, kernels and bindings shared by
// the passes. Mirrors src/sph/gpu.rs (SphGpuParams). Particle arrays are in sorted order.
#ifndef SPH_COMMON_GLSL
#define SPH_COMMON_GLSL
#include "common/index.glsl"
#include "../primitives/nb_common.glsl"
#define NB_B_KEYS 1
#define NB_B_START 2
#define NB_B_END 3
#define NB_B_BOX 4
#include "../primitives/neighbors.glsl"

struct SphParams {
    vec4 gravity;      // xyz, w = dt
    vec4 domain_min;   // xyz, w = restitution
    vec4 domain_max;   // xyz, w = friction
    float h;
    float mass;
    float rest_density;
    float stiffness;   // k (ideal gas) or B (Tait)
    float viscosity;
    float tension;
    float tension_threshold;
    float gamma;       // Tait exponent
    uint eos;          // 0: p = k (rho - rho0), 1: Tait
    uint clamp_negative;
    uint colliders;
    uint pad;
    float poly6;       // 315 / (64 pi h^9)
    float poly6_grad;  // -945 / (32 pi h^9)
    float spiky_grad;  // -45 / (pi h^6)
    float visc_lap;    // 45 / (pi h^6)
};
layout(std430, binding = 0) readonly buffer Params { SphParams P; };          // binding 0
layout(std430, binding = 5) buffer Pos { vec4 pos[]; };                      // binding 5: xyz
layout(std430, binding = 6) buffer Vel { vec4 vel[]; };                      // binding 6: v(t)
layout(std430, binding = 7) buffer Rho { vec2 rho_p[]; };                    // binding 7: density, pressure
layout(std430, binding = 8) buffer Acc { vec4 acc[]; };                      // binding 8: acceleration

float pressure_of(float rho) {
    float p = P.eos == 1u ? P.stiffness * (pow(rho / P.rest_density, P.gamma) - 1.0)
                          : P.stiffness * (rho - P.rest_density);
    return P.clamp_negative != 0u ? max(p, 0.0) : p;
}
#endif
