#version 450
// The driving force (eq. 7): f_i = c_cp sum_j rho_j grad W_spiky(r_i - r_j, h_c) over
// control particles j within h_c (their own grid), each term scaled by the adaptive
// factor; added to the acceleration as f_i / rho_i. With K > 0, a velocity term pulls the
// fluid velocity towards the control particles' (kernel-weighted mean).
// Ours, after Thuerey et al. 2006: a deficit attraction towards the control particles
// within the reach R that hold less than rest density (each weighted by its deficit
// 1 - rho_j / rho0 and (1 - r/R)^2, normalised by the deficits' weight or 1: a filled
// neighbourhood pulls nothing, a few empty particles nearby pull at full strength, a lone
// far one a little), and a damping of the velocity relative to the character's there
// (the mean control velocity, weighted alike). Both are a field on the control grid
// (aggregate.comp sums each cell, field.comp evaluates at cell centres) read trilinearly.
// --control-every K: CONTROL_REFRESH 1 walks and stores eq. 7's sum and the velocity
// term's mean (cforce, cvmean); CONTROL_REFRESH 0 reads them back (gathered into this
// step's order by the control hook) and applies them with this step's density and velocity.
#include "common.glsl"
void main() {
    uint i = global_id();
    if (i >= sph_live() || !controlled(i)) return;
    vec3 xi = pos[i].xyz;
#if CONTROL_REFRESH == 1
    float hc = C.radius, hc2 = hc * hc;
    float fc = fine_cell();
    ivec3 fd = ivec3(fine_dims());
    ivec3 c0 = clamp(ivec3(floor((xi - C.grid.xyz) / fc)), ivec3(0), fd - 1);
    vec3 f = vec3(0.0);
    vec3 vsum = vec3(0.0);
    float wsum = 0.0;
    // Eq. 7 and the velocity term walk the control particles within h_c; with both off
    // (c_cp = K = 0) the walk is skipped. The set is sorted on cells of h_c / 2 numbered x
    // fastest: each of the 5 x 5 rows along x around xi is one contiguous range, clipped to
    // the sphere's chord in that row (about a third of the candidates of 27 cells of h_c;
    // walking 125 cells one by one instead cost more than it saved on llvmpipe).
    if (C.pressure != 0.0 || C.velocity > 0.0) for (int dz = -2; dz <= 2; ++dz) for (int dy = -2; dy <= 2; ++dy) {
        ivec2 cyz = c0.yz + ivec2(dy, dz);
        if (any(lessThan(cyz, ivec2(0))) || any(greaterThanEqual(cyz, fd.yz))) continue;
        ivec2 span = row_span(xi, cyz, fc, hc);
        if (span.x > span.y) continue;
        int x0 = clamp(span.x, 0, fd.x - 1), x1 = clamp(span.y, 0, fd.x - 1);
        uvec2 run = fine_range(fine_id(ivec3(x0, cyz)), fine_id(ivec3(x1, cyz)));
        for (uint j = run.x; j < run.y; ++j) {
            vec3 d = xi - cpos[j].xyz;
            float r2 = dot(d, d);
            if (r2 >= hc2 || r2 == 0.0) continue;
            float r = sqrt(r2);
            float q = hc - r;
            vec4 vw = cvw[j];
            // grad W_spiky = spiky_grad (h - r)^2 d / r with spiky_grad < 0 points from i
            // to j, so a positive c_cp pulls i towards j.
            f += vw.w * (C.spiky_grad * q * q / r) * d;
            float w = q * q * q;
            vsum += w * vw.xyz;
            wsum += w;
        }
    }
    vec4 vmean = wsum > 0.0 ? vec4(vsum / wsum, 1.0) : vec4(0.0);
    cforce[i] = vec4(f, 0.0);
    cvmean[i] = vmean;
#elif CONTROL_REFRESH == 0
    vec3 f = cforce[i].xyz;
    vec4 vmean = cvmean[i];
#else
#error "CONTROL_REFRESH is neither 0 nor 1"
#endif
    float rho = max(rho_p[i].x, 1e-6);
    vec3 a = f / rho;
    if (vmean.w > 0.0) a += C.velocity * (vmean.xyz - vel[i].xyz);
    if (C.attraction > 0.0 || C.damping > 0.0) {
        // The field of field.comp at xi, trilinear between cell centres (clamped at the
        // grid's faces); the damping fades with the interpolated mask.
        vec3 u = (xi - C.grid.xyz) / C.grid.w - 0.5;
        ivec3 hi = ivec3(C.dims.xyz) - 1;
        ivec3 b = clamp(ivec3(floor(u)), ivec3(0), hi);
        vec3 t = clamp(u - vec3(b), 0.0, 1.0);
        vec3 pull = vec3(0.0);
        vec4 vchar = vec4(0.0);
        for (int n = 0; n < 8; ++n) {
            ivec3 o = ivec3(n & 1, (n >> 1) & 1, n >> 2);
            ivec3 c = min(b + o, hi);
            vec3 wt = mix(1.0 - t, t, vec3(o));
            float w = wt.x * wt.y * wt.z;
            uint id = (uint(c.z) * C.dims.y + uint(c.y)) * C.dims.x + uint(c.x);
            pull += w * cfield[2 * id].xyz;
            vchar += w * cfield[2 * id + 1];
        }
        a += pull + C.damping * (vchar.xyz - vchar.w * vel[i].xyz);
    }
    acc[i].xyz += a;
}
