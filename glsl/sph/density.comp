#version 450
// Density (poly6, self included) and pressure from the equation of state.
#include "common.glsl"
void main() {
    uint i = global_id();
    if (i >= sph_live() || pos[i].w < 0.0) return;  // past the live, or dead
    vec3 xi = pos[i].xyz;
    float h2 = P.h * P.h;
    float sum = 0.0;
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        float r2 = dot(d, d);
        if (r2 < h2) { float q = h2 - r2; sum += q * q * q; }
    NB_END
    float rho = P.mass * P.poly6 * sum;
    rho_p[i] = vec2(rho, pressure_of(rho));
}
