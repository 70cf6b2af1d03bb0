#version 450
// The state-preserving step (Euler or Verlet) over the alive list: forces, integration,
// collisions, events and death. A survivor is appended to the other alive list, a dead particle
// pushed on the dead stack: the lists stay compact with no CPU read-back.
#include "common/index.glsl"
#include "state.glsl"
#include "noise.glsl"
#include "collide.glsl"
#ifdef SUBGROUP
#extension GL_KHR_shader_subgroup_ballot : require
#endif

// Reserve `n` entries (n = 1 or 0 per invocation) at counter `which` (0, 1: the alive
// lists; 2: the dead stack) for every invocation calling it; the first index of each.
// With subgroups one atomic per subgroup instead of one per particle: a million appends
// to one address serialise otherwise.
uint reserve(uint which, bool take) {
#ifdef SUBGROUP
    uvec4 ballot = subgroupBallot(take);
    uint total = subgroupBallotBitCount(ballot);
    uint base = 0u;
    if (subgroupElect() && total > 0u) {
        base = which == 2u ? uint(atomicAdd(c.dead_count, int(total))) : atomicAdd(c.alive[which], total);
    }
    return subgroupBroadcastFirst(base) + subgroupBallotExclusiveBitCount(ballot);
#else
    if (!take) return 0u;
    return which == 2u ? uint(atomicAdd(c.dead_count, 1)) : atomicAdd(c.alive[which], 1u);
#endif
}

// Record an event for the spawn pass (a full list drops it, counted).
void record_event(vec3 p, vec3 v, vec3 n, uint kind) {
    uint k = atomicAdd(ev_count, 1u);
    if (k < uint(ev.length())) ev[k] = Event(vec4(p, float(kind)), vec4(v, 0.0), vec4(n, 0.0));
    else atomicAdd(c.events_dropped, 1u);
}

// Acceleration at p moving with v, at time t.
vec3 accel(vec3 p, vec3 v, float t, uint slot) {
    vec3 a = sp.gravity.xyz + sp.wind.w * (sp.wind.xyz - v);
    if (sp.grid_dims.w == 1u) a += steer[slot].xyz;
    for (uint k = 0u; k < sp.counts.x; k++) {
        Force f = sp.forces[k];
        uint kind = uint(f.a.w);
        if (kind == F_ATTRACTOR) {
            vec3 d = f.a.xyz - p;
            float r2 = dot(d, d);
            a += d * inversesqrt(max(r2, 1e-12)) * f.b.x / (r2 + f.b.y);
        } else if (kind == F_VORTEX) {
            vec3 axis = normalize(f.b.xyz);
            vec3 d = p - f.a.xyz;
            vec3 radial = d - dot(d, axis) * axis;
            float r2 = dot(radial, radial);
            // Tangential pull, 1 / (r^2 + 1) past the core (its radius is 1 m / sqrt).
            a += cross(axis, radial) * f.b.w / (r2 + 1.0);
        } else if (kind == F_CURL) {
            a += f.b.x * curl_noise(p * f.b.y + vec3(0.0, 0.0, t * f.b.z));
        }
    }
    return a;
}

// Boids: the speed kept within [min, max].
vec3 limit_speed(vec3 v) {
    if (sp.grid_dims.w != 1u) return v;
    float s = length(v), lo = sp.boids[3].y, hi = sp.boids[0].z;
    if (s > hi) return v * (hi / s);
    if (s < lo) return s > 1e-9 ? v * (lo / s) : vec3(lo, 0.0, 0.0);
    return v;
}

void main() {
    uint i = global_id();
    if (i >= c.alive[pc.cur]) return;
    uint slot = alive[pc.cur * pc.capacity + i];
    vec4 P = pos[slot], V = vel[slot];
    vec3 p = P.xyz;
    float dt = pc.dt, t = pc.source.w;
    float keep = exp(-sp.death.x * dt);  // damping v = c v, c per step from a rate
    vec3 v;
    if (sp.counts2.y == I_VERLET) {
        vec3 vel_est = (p - V.xyz) / dt;
        vec3 next = p + (p - V.xyz) * keep + accel(p, vel_est, t, slot) * dt * dt;
        v = limit_speed((next - p) / dt);
        p += v * dt;
    } else {
        v = V.xyz + accel(p, V.xyz, t, slot) * dt;
        v = limit_speed(v * keep);
        p += v * dt;
    }
    bool killed = false, hit = false;
    vec3 hit_n = vec3(0.0);
    for (uint k = 0u; k < sp.counts.y; k++) {
      bool body = uint(sp.colliders[k].a.w) == C_CHARACTER;
      for (uint q = 0u; q < (body ? pc.capsules : 1u); q++) {
        Collider col = sp.colliders[k];
        if (body) col = posed_capsule(col, capsules[2u * q], capsules[2u * q + 1u]);
        vec3 n;
        if (contact(col, p, n)) {
            hit = true;
            hit_n = n;
            if (col.c.w > 0.5) killed = true;
            // Split the velocity: the normal part bounces with restitution e, the
            // tangential part loses the friction fraction.
            float vn = dot(v, n);
            if (vn < 0.0) {
                vec3 vt = v - vn * n;
                v = -col.c.x * vn * n + (1.0 - col.c.y) * vt;
            }
        }
      }
    }
    float age = P.w + dt;
    prev[slot].xyz = P.xyz;
    uint cause = 0u, events = sp.counts2.z;
    bool hit_event = hit && (events & EV_COLLISION) != 0u;
    if (hit_event) record_event(p, v, hit_n, KIND_COLLISION);
    if (hit_event && (events & EV_KEEP_PARENT) == 0u) cause = 5u;  // its type changed
    else if (killed) cause = 4u;
    else if (age >= V.w) cause = 1u;
    else if (sp.death.y > 0.0 && distance(p, pc.source.xyz) > sp.death.y) cause = 3u;
    else if (sp.death.z > 0.5) {
        vec4 clip = pc.view_proj * vec4(p, 1.0);
        if (clip.w <= 0.0 || any(greaterThan(abs(clip.xy), vec2(clip.w * 1.1)))) cause = 2u;
    }
    if (cause == 1u && (events & EV_DEATH) != 0u) record_event(p, v, vec3(0.0), KIND_DEATH);
    // Every invocation reaches both reservations (subgroup operations).
    uint d = reserve(2u, cause != 0u);
    uint a = reserve(1u - pc.cur, cause == 0u);
    if (cause != 0u) {
        pos[slot] = vec4(p, -1.0);
        vel[slot] = vec4(0.0);
        if (cause == 1u) atomicAdd(c.died_life, 1u);
        else if (cause == 2u) atomicAdd(c.died_view, 1u);
        else if (cause == 3u) atomicAdd(c.died_distance, 1u);
        else if (cause == 4u) atomicAdd(c.died_collision, 1u);
        else atomicAdd(c.changed, 1u);
        dead[d] = slot;
        return;
    }
    pos[slot] = vec4(p, age);
    vel[slot] = vec4(sp.counts2.y == I_VERLET ? p - v * dt : v, V.w);
    alive[(1u - pc.cur) * pc.capacity + a] = slot;
}
