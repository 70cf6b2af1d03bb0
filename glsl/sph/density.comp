#version 450
// Density (poly6, self included, plus the solid boundary's: boundary.glsl) and pressure
// from the equation of state.
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
    vec3 g;
    float rate;
    float rho = P.mass * P.poly6 * sum + P.rest_density * boundary(xi, vec3(0.0), g, rate);
    rho_p[i] = vec2(rho, pressure_of(rho));
}
