// SPH after Müller et al. 2003 / Kelager 2006: parameters, kernels and bindings shared by
// the passes. Bindings: SphIo in src/sim/sph/solver.rs (SPH_B_* defines); SphParams and
// Collider mirror SphGpuParams and GpuCollider in src/sim/sph/params.rs (field offsets tested).
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
    uint solver;       // SOLVER_WCSPH, _PCISPH, _DFSPH, _PBF
    uint min_iter;     // pressure solves: iterations at least, at most
    uint max_iter;
    float density_target;     // mean density error a solve stops at
    float divergence_target;  // dfsph: mean compression rate * dt
    float proto_grad2;        // sum |V grad W|^2 over a full neighbourhood, V = m / rho0
    float pbf_relaxation;
    float scorr_k;
    float scorr_n;
    float scorr_inv_w;        // 1 / W_poly6(dq)
    float xsph;
    float vorticity;
    uint list_max;            // dfsph: neighbour list length (0: off)
    uint kernel;              // KERNEL_MULLER, _CUBIC, _WENDLAND (kernel.glsl)
    float kernel_k;           // cubic's or wendland's normalisation
    uint min_neighbors;       // dfsph: fewer, and the divergence solve leaves a particle out
    uint div_min_iter;        // dfsph: the divergence solve's least iterations
    float dt_prev;            // the previous step's dt (warm starts rescale by it)
    float cfl;                // > 0: the step's dt from its own velocities (cfl.comp)
    float dt_max;             // with cfl: the largest step
    float cfl_speed;          // with cfl: the least speed it divides by (wcsph: c)
    float wall_offset;        // the walls' terms take a particle this much farther
    uint pad1, pad2;
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

// Reflect the velocity's normal part (n points into the fluid side), damp the tangent.
vec3 respond(vec3 v, vec3 n, vec3 wall_v) {
    vec3 rel = v - wall_v;
    float vn = dot(rel, n);
    if (vn >= 0.0) return v;
    vec3 vt = rel - vn * n;
    return wall_v + vt * (1.0 - P.domain_max.w) - P.domain_min.w * vn * n;
}

// Collision response against the colliders and the domain box: x pushed out to half a
// rest spacing from the surface (where a lattice particle rests next to a wall, and the
// boundary's density is the lattice's missing part; at the surface itself it would add
// rho0 / 2), both velocities (leapfrog's half step and full; the same one twice
// elsewhere) answered with restitution and friction; a final clamp, so no particle ever
// leaves the domain.
float rest_margin() { return 0.5 * pow(P.mass / P.rest_density, 1.0 / 3.0); }
// A collider's signed distance at x (negative inside the solid) and its surface normal
// there, pointing into the fluid.
float collider_distance(Collider col, vec3 x, out vec3 n) {
    uint kind = uint(col.b.w);
    if (kind == 0u) {
        n = col.a.xyz;
        return dot(n, x) - col.a.w;
    }
    vec3 q = col.a.xyz;
    if (kind == 2u) {
        vec3 ab = col.b.xyz - col.a.xyz;
        float t = clamp(dot(x - col.a.xyz, ab) / max(dot(ab, ab), 1e-20), 0.0, 1.0);
        q = col.a.xyz + t * ab;
    }
    vec3 d = x - q;
    float len = length(d);
    n = len > 1e-12 ? d / len : vec3(0.0, 1.0, 0.0);
    return len - col.a.w;
}
void collide(inout vec3 x, inout vec3 va, inout vec3 vb) {
    float r = rest_margin();
    for (uint c = 0u; c < P.colliders; ++c) {
        Collider col = cols[c];
        vec3 n;
        float depth = r - collider_distance(col, x, n);
        if (depth > 0.0) {
            x += depth * n;
            va = respond(va, n, col.vel.xyz);
            vb = respond(vb, n, col.vel.xyz);
        }
    }
    // The margin never more than half the domain.
    vec3 lo = P.domain_min.xyz, hi = P.domain_max.xyz;
    vec3 m = min(vec3(r), 0.5 * (hi - lo));
    lo += m;
    hi -= m;
    for (int k = 0; k < 3; ++k) {
        vec3 n = vec3(0.0);
        n[k] = 1.0;
        if (x[k] < lo[k]) { x[k] = lo[k]; va = respond(va, n, vec3(0.0)); vb = respond(vb, n, vec3(0.0)); }
        if (x[k] > hi[k]) { x[k] = hi[k]; va = respond(va, -n, vec3(0.0)); vb = respond(vb, -n, vec3(0.0)); }
    }
    x = clamp(x, lo, hi);
}

float pressure_of(float rho) {
    float p = P.eos == EOS_TAIT ? P.stiffness * (pow(rho / P.rest_density, P.gamma) - 1.0)
                          : P.stiffness * (rho - P.rest_density);
    return P.clamp_negative != 0u ? max(p, 0.0) : p;
}
#include "boundary.glsl"
#endif
