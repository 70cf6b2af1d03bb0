#version 450
// Births: one invocation per new particle (mode 0), or per event of a parent system
// (mode = the event kind: its children). Euler and Verlet pop a free slot from the dead
// stack (none left: the birth is refused and counted) and append it to the alive list the
// update reads; closed form writes the ring's next slots (a live particle there is
// overwritten and counted). Every attribute is mean + rand * variance, rand in [-1, 1).
#include "common/index.glsl"
#include "state.glsl"

// A point on the character's skinned surface: a triangle by bind-pose area (binary
// search of the CDF), uniform within it; its unit normal in `n`.
vec3 mesh_point(inout uint s, out vec3 n) {
    float u = rnd(s);
    uint lo = 0u, hi = pc.triangles - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) >> 1;
        if (mesh_cdf[mid] < u) lo = mid + 1u; else hi = mid;
    }
    vec3 a = mesh_pos[mesh_idx[3u * lo]].xyz, b = mesh_pos[mesh_idx[3u * lo + 1u]].xyz,
         c = mesh_pos[mesh_idx[3u * lo + 2u]].xyz;
    vec3 cr = cross(b - a, c - a);
    n = dot(cr, cr) > 1e-20 ? normalize(cr) : vec3(0.0, 1.0, 0.0);
    float r1 = sqrt(rnd(s)), r2 = rnd(s);
    return (1.0 - r1) * a + r1 * (1.0 - r2) * b + r1 * r2 * c;
}

vec3 shape_point(inout uint s) {
    uint shape = uint(sp.emitter.w);
    vec3 e = sp.extent.xyz;
    bool surface = sp.extent.w > 0.5;
    if (shape == E_BOX) {
        vec3 p = srnd3(s);
        if (surface) {  // push one random axis to a face
            uint k = min(uint(rnd(s) * 3.0), 2u);
            p[k] = p[k] < 0.0 ? -1.0 : 1.0;
        }
        return p * e;
    }
    if (shape == E_SPHERE) {
        // Uniform direction; radius cube root for a uniform volume.
        float z = srnd(s), phi = 6.2831853 * rnd(s);
        vec3 d = vec3(sqrt(max(1.0 - z * z, 0.0)) * vec2(cos(phi), sin(phi)), z);
        return d * e.x * (surface ? 1.0 : pow(rnd(s), 1.0 / 3.0));
    }
    if (shape == E_DISC) {
        vec3 n = normalize(sp.normal.xyz);
        vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
        vec3 b = cross(n, t);
        float r = e.x * (surface ? 1.0 : sqrt(rnd(s))), phi = 6.2831853 * rnd(s);
        return r * (cos(phi) * t + sin(phi) * b);
    }
    return vec3(0.0);
}

// An orthonormal basis (t, n, b) about unit n.
void basis(vec3 n, out vec3 t, out vec3 b) {
    t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
    b = cross(n, t);
}

// The particle's own velocity: mean + rand x variance, its direction spread in a cone.
vec3 own_velocity(inout uint s) {
    vec3 v = sp.vel_mean.xyz + srnd3(s) * sp.vel_var.xyz;
    float spread = sp.vel_mean.w;  // cone half-angle (rad) about the mean direction
    if (spread > 0.0 && dot(sp.vel_mean.xyz, sp.vel_mean.xyz) > 0.0) {
        vec3 a = normalize(sp.vel_mean.xyz), t, b;
        basis(a, t, b);
        float z = mix(cos(spread), 1.0, rnd(s)), phi = 6.2831853 * rnd(s);  // uniform on the cap
        float r = sqrt(max(1.0 - z * z, 0.0));
        v = length(v) * (z * a + r * (cos(phi) * t + sin(phi) * b));
    }
    return v;
}

// The attributes every birth draws after its position and velocity (in this order).
void attributes(inout uint s, out float size, out float life, out vec4 col) {
    vec2 sl = sp.scalar_mean.xy + vec2(srnd(s), srnd(s)) * sp.scalar_var.xy;
    size = max(sl.x, 0.0);
    life = max(sl.y, 1e-4);
    col = clamp(sp.color_mean + srnd4(s) * sp.color_var, 0.0, 1.0);
}

// A stateful birth at p moving with v: pop a free slot (none: refused, counted) and
// append it to the alive list the next update reads (or, after it, the one drawn).
void born(vec3 p, vec3 v, inout uint s, bool spawned) {
    int d = atomicAdd(c.dead_count, -1) - 1;
    if (d < 0) {  // no free slot: the budget is spent
        atomicAdd(c.dead_count, 1);
        if (spawned) atomicAdd(c.spawn_refused, 1u);
        else atomicAdd(c.refused, 1u);
        return;
    }
    uint slot = dead[d];
    float size, life;
    vec4 col;
    attributes(s, size, life, col);
    pos[slot] = vec4(p, 0.0);
    // Verlet keeps the previous position: a Taylor step back, exact for gravity.
    vec3 back = p - v * pc.dt + 0.5 * sp.gravity.xyz * pc.dt * pc.dt;
    vel[slot] = vec4(sp.counts2.y == I_VERLET ? back : v, life);
    prev[slot] = vec4(p, size);
    color[slot] = col;
    uint a = atomicAdd(c.alive[pc.cur], 1u);
    alive[pc.cur * pc.capacity + a] = slot;
    if (spawned) atomicAdd(c.spawned, 1u);
    else atomicAdd(c.births, 1u);
}

// Children of one event of the parent system (its list is bound as `ev`).
void spawn(uint i) {
    if (i >= min(ev_count, uint(ev.length()))) return;
    Event e = ev[i];
    if (uint(e.p.w) != pc.mode) return;
    uint s = pcg(pc.seed ^ pcg(i + 0x9e3779b9u));
    uint n = uint(max(pc.source.x + srnd(s) * pc.source.y + rnd(s), 0.0));
    vec3 normal = e.n.xyz, t, b;
    bool along = pc.births == 1u && dot(normal, normal) > 0.5;
    if (along) basis(normal, t, b);
    for (uint k = 0u; k < n; k++) {
        vec3 v = own_velocity(s);
        if (along) v = v.x * t + v.y * normal + v.z * b;  // +y onto the normal
        vec3 p = e.p.xyz + sp.offset_mean.xyz + srnd3(s) * sp.offset_var.xyz;
        born(p, v + pc.source.z * e.v.xyz, s, true);
    }
}

void main() {
    uint i = global_id();
    if (pc.mode != 0u) {
        spawn(i);
        return;
    }
    if (i >= pc.births) return;
    uint s = pcg(pc.seed ^ pcg(i + 0x9e3779b9u));
    vec3 p, v;
    if (uint(sp.emitter.w) == E_MESH) {
        if (pc.triangles == 0u) return;  // no character bound (the scene validates this)
        vec3 n, t, b;
        p = mesh_point(s, n) + sp.offset_mean.xyz + srnd3(s) * sp.offset_var.xyz;
        basis(n, t, b);
        v = own_velocity(s);
        v = v.x * t + v.y * n + v.z * b;  // +y onto the surface normal
    } else {
        p = pc.source.xyz + shape_point(s) + sp.offset_mean.xyz + srnd3(s) * sp.offset_var.xyz;
        v = own_velocity(s);
    }
    if (sp.counts2.y != I_CLOSED) {
        born(p, v, s, false);
        return;
    }
    uint slot = (pc.head + i) % pc.capacity;
    vec4 old = pos[slot];
    if (old.w >= 0.0 && pc.source.w - old.w < vel[slot].w) atomicAdd(c.overwritten, 1u);
    float size, life;
    vec4 col;
    attributes(s, size, life, col);
    pos[slot] = vec4(p, pc.source.w);  // birth time
    vel[slot] = vec4(v, life);
    prev[slot] = vec4(p, size);
    color[slot] = col;
    atomicAdd(c.births, 1u);
}
