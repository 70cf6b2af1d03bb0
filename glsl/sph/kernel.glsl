// The smoothing kernel of densities and pressure gradients, P.kernel (src/sim/sph/kernel.rs
// has the formulas, and the same in f64): KERNEL_MULLER, the thesis's poly6 densities with
// spiky gradients; KERNEL_CUBIC, the cubic spline; KERNEL_WENDLAND, Wendland C2. Support
// h; P.kernel_k: cubic's or wendland's normalisation. Host-checked: no other value comes.
#ifndef SPH_KERNEL_GLSL
#define SPH_KERNEL_GLSL
float kernel_w(float r2) {
    float h2 = P.h * P.h;
    if (r2 >= h2) return 0.0;
    if (P.kernel == KERNEL_MULLER) { float q = h2 - r2; return P.poly6 * q * q * q; }
    float q = sqrt(r2) / P.h;
    float w = 1.0 - q;
    if (P.kernel == KERNEL_CUBIC) return P.kernel_k * (q <= 0.5 ? 6.0 * q * q * (q - 1.0) + 1.0 : 2.0 * w * w * w);
    return P.kernel_k * w * w * w * w * (4.0 * q + 1.0);
}
// grad W(d), r2 = |d|^2 < h^2; 0 where |d| <= 1e-6 h (no direction).
vec3 kernel_grad(vec3 d, float r2) {
    float r = sqrt(r2);
    if (r <= 1e-6 * P.h) return vec3(0.0);
    float q = r / P.h, w = 1.0 - q, s;
    if (P.kernel == KERNEL_MULLER) s = P.spiky_grad * (P.h - r) * (P.h - r) / r;
    else if (P.kernel == KERNEL_CUBIC) s = q <= 0.5 ? 6.0 * P.kernel_k / (P.h * P.h) * (3.0 * q - 2.0)
                                                   : -6.0 * P.kernel_k / (P.h * r) * w * w;
    else s = -20.0 * P.kernel_k / (P.h * P.h) * w * w * w;
    return s * d;
}
// A solid half-space at distance d (u = d / h): its density / rho0 I(u) and its
// |sum V grad W| A(u) (muller: spiky's), both closed-form integrals (kernel.rs).
// d: the distance to the surface (wall_offset added: kernel.rs says why).
float solid_density(float d) {
    float u = clamp((d + P.wall_offset) / P.h, 0.0, 1.0), w = 1.0 - u, u2 = u * u;
    if (P.kernel == KERNEL_MULLER) {
        float f = u * (1.0 + u2 * (-4.0 / 3.0 + u2 * (6.0 / 5.0 + u2 * (-4.0 / 7.0 + u2 / 9.0))));
        return 0.5 - 315.0 / 256.0 * f;
    }
    if (P.kernel == KERNEL_CUBIC) {
        if (u <= 0.5) return 0.5 + u * (-1.4 + u2 * (8.0 / 3.0 + u2 * (-4.8 + 3.2 * u)));
        float w2 = w * w;
        return 8.0 / 15.0 * w2 * w2 * w * (2.0 * u + 1.0);
    }
    float w3 = w * w * w;
    return 0.5 * w3 * w3 * (3.0 * u2 + 3.0 * u + 1.0);
}
float solid_push(float d) {
    float u = clamp((d + P.wall_offset) / P.h, 0.0, 1.0), w = 1.0 - u, w4 = w * w * w * w;
    if (P.kernel == KERNEL_MULLER) return 30.0 / P.h * (w4 / 4.0 - w4 * w / 5.0);
    if (P.kernel == KERNEL_CUBIC) {
        float u2 = u * u;
        if (u <= 0.5) return (1.4 + u2 * (-8.0 + u2 * (24.0 - 19.2 * u))) / P.h;
        return 1.6 * w4 * (4.0 * u + 1.0) / P.h;
    }
    return 1.5 * w4 * w * (8.0 * u * u + 5.0 * u + 1.0) / P.h;
}
#endif
