// SPH after Müller et al. 2003 / Kelager 2006: parameters, kernels and bindings shared by
// the passes. Bindings: SphIo in src/sph/solver.rs (SPH_B_* defines); SphParams and
// Collider mirror SphGpuParams and GpuCollider in src/sph/params.rs (field offsets tested).
// Particle arrays are in sorted order.
#ifndef SPH_COMMON_GLSL
#define SPH_COMMON_GLSL
#include "common/index.glsl"
#include "../primitives/nb_common.glsl"
#define NB_B_KEYS SPH_B_NB_KEYS
#define NB_B_START SPH_B_NB_START
#define NB_B_END SPH_B_NB_END
#define NB_B_BOX SPH_B_NB_BOX
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
    uint eos;          // EOS_IDEAL: p = k (rho - rho0), EOS_TAIT
    uint clamp_negative;
    uint colliders;
    uint live;         // slots at and past it are dead (emission); see sph_live()
    float poly6;       // 315 / (64 pi h^9)
    float poly6_grad;  // -945 / (32 pi h^9)
    float spiky_grad;  // -45 / (pi h^6)
    float visc_lap;    // 45 / (pi h^6)
};
struct Collider {
    vec4 a;    // plane: normal, w = offset (fluid where dot(n, x) >= w); sphere/capsule: point, w = radius
    vec4 b;    // capsule: second point; w = kind (0 plane, 1 sphere, 2 capsule)
    vec4 vel;  // collider velocity (moving colliders)
};
layout(std430, binding = SPH_B_PARAMS) readonly buffer Params { SphParams P; };
layout(std430, binding = SPH_B_POS) buffer Pos { vec4 pos[]; };          // xyz
layout(std430, binding = SPH_B_VEL) buffer Vel { vec4 vel[]; };          // v(t)
layout(std430, binding = SPH_B_RHO_P) buffer RhoP { vec2 rho_p[]; };     // density, pressure
layout(std430, binding = SPH_B_ACC) buffer Acc { vec4 acc[]; };          // acceleration
layout(std430, binding = SPH_B_VHALF) buffer Vhalf { vec4 vhalf[]; };    // v(t - dt/2)
layout(std430, binding = SPH_B_COLLIDERS) readonly buffer Colliders { Collider cols[]; };

// Particles the passes cover: live ones come first (the sort puts dead slots last).
uint sph_live() { return min(pc.n, P.live); }

float pressure_of(float rho) {
    float p = P.eos == EOS_TAIT ? P.stiffness * (pow(rho / P.rest_density, P.gamma) - 1.0)
                          : P.stiffness * (rho - P.rest_density);
    return P.clamp_negative != 0u ? max(p, 0.0) : p;
}
#endif
