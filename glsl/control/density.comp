#version 450
// Fluid density at every control particle (poly6 over the fluid grid, controlled groups),
// its weight in eq. 7 (c_cp rho_j times the adaptive factor) and its velocity: once per
// control particle here, not once per fluid neighbour in force.comp's walk.
#include "common.glsl"
void main() {
    uint j = global_id();
    if (j >= C.dims.w) return;
    // Parked slots (rays) sort after the live ones: no density there.
    if (j >= C.live) { crho[j] = 0.0; cvw[j] = vec4(0.0); return; }
    vec3 xj = cpos[j].xyz;
    float h2 = P.h * P.h;
    float sum = 0.0;
    NB_BEGIN(xj, P.h, i)
        if (!controlled(i)) continue;
        vec3 d = xj - pos[i].xyz;
        float r2 = dot(d, d);
        if (r2 < h2) { float q = h2 - r2; sum += q * q * q; }
    NB_END
    float rho = P.mass * P.poly6 * sum;
    crho[j] = rho;
    cvw[j] = vec4(control_velocity(j), C.pressure * rho * adaptive_factor(rho));
}
