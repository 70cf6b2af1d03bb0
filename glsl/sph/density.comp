#version 450
// Density (the kernel's, self included, plus the solid boundary's: boundary.glsl) and pressure
// from the equation of state.
#include "common.glsl"
void main() {
    uint i = global_id();
    if (i >= sph_live() || pos[i].w < 0.0) return;  // past the live, or dead
    vec3 xi = pos[i].xyz;
    float sum = 0.0;
    NB_BEGIN(xi, P.h, j)
        vec3 d = xi - pos[j].xyz;
        sum += kernel_w(dot(d, d));
    NB_END
    vec3 g;
    float rate;
    float rho = P.mass * sum + P.rest_density * boundary(xi, vec3(0.0), g, rate);
    rho_p[i] = vec2(rho, pressure_of(rho));
}
