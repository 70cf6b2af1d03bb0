//! Position based fluids as Macklin & Müller (2013) write it (their Algorithm 1), in f64
//! with brute-force neighbours, written from the paper and not from glsl/sph/pbf.comp:
//! velocities and predicted positions from the external force, neighbours found once at
//! the predicted positions, then `iterations` Jacobi rounds of
//! lambda_i = -C_i / (sum_k |grad_k C_i|^2 + eps) over all particles, then
//! dp_i = (m / rho0) sum_j (lambda_i + lambda_j) grad W(p_i - p_j) over all, then
//! p_i += dp_i; at the end v_i = (p_i - x_i) / dt. C_i = rho_i / rho0 - 1 with
//! rho_i = sum_j m W(p_i - p_j): the paper writes 1 / rho0 for unit masses, here m / rho0.
//! Two choices the paper leaves open: only a compressed particle constrains (C_i at least
//! 0, so a free surface is not pulled in), and eps is `relaxation` times a full
//! neighbourhood's sum_k |grad_k C_i|^2 (`params::proto_grad2`: a simple cubic lattice at
//! the rest spacing), the paper's "user specified relaxation parameter" made independent
//! of the resolution.
//! Kernels as the paper's: poly6 densities, spiky gradients. The tensile correction
//! s_corr, collisions, XSPH and vorticity confinement are not part of it (a comparison
//! sets them to 0 and keeps the particles off the walls).
use super::params::FluidParams;
use super::v3::{axpy, dot, neighbours, sub, xyz, Smoothing, V3};

/// One PBF step of `pos`, `vel` (xyz) under `accel` (the external acceleration): the
/// positions and velocities after it, in f64. `requery`: neighbours found again before
/// every iteration, as a grid search from the moving positions does (the paper keeps
/// N_i(p_i) of the prediction: a pair that comes within h during the solve counts nowhere).
pub fn step(
    f: &FluidParams,
    dt: f64,
    accel: V3,
    pos: &[[f32; 4]],
    vel: &[[f32; 4]],
    iterations: u32,
    requery: bool,
) -> (Vec<V3>, Vec<V3>) {
    let f = &f.resolved().unwrap_or_else(|_| f.clone());
    let n = pos.len();
    let (h, m, rho0) = (f.h as f64, f.mass as f64, f.rest_density as f64);
    let sm = Smoothing::new(f.kernel(), h);
    let (w, grad) = (|d: V3| sm.w(d), |d: V3| sm.grad(d));
    let c = m / rho0;
    let eps = f.pbf.relaxation as f64 * super::params::proto_grad2(f);
    let x = xyz(pos);
    // v <- v + dt f_ext; p <- x + dt v.
    let v: Vec<V3> = vel
        .iter()
        .map(|p| axpy(dt, accel, [p[0] as f64, p[1] as f64, p[2] as f64]))
        .collect();
    let mut p: Vec<V3> = (0..n).map(|i| axpy(dt, v[i], x[i])).collect();
    // N_i(p_i), once (the paper), or before every iteration (`requery`).
    let mut nb = neighbours(&p, h);
    for it in 0..iterations {
        if requery && it > 0 {
            nb = neighbours(&p, h);
        }
        let lambda: Vec<f64> = (0..n)
            .map(|i| {
                let rho =
                    m * (w([0.0; 3]) + nb[i].iter().map(|&j| w(sub(p[i], p[j]))).sum::<f64>());
                let ci = (rho / rho0 - 1.0).max(0.0);
                let (mut gi, mut sum) = ([0.0; 3], 0.0);
                for &j in &nb[i] {
                    let g = grad(sub(p[i], p[j])).map(|x| x * c);
                    gi = axpy(1.0, g, gi);
                    sum += dot(g, g);
                }
                -ci / (dot(gi, gi) + sum + eps)
            })
            .collect();
        let dp: Vec<V3> = (0..n)
            .map(|i| {
                nb[i].iter().fold([0.0; 3], |acc, &j| {
                    axpy(c * (lambda[i] + lambda[j]), grad(sub(p[i], p[j])), acc)
                })
            })
            .collect();
        for i in 0..n {
            p[i] = axpy(1.0, dp[i], p[i]);
        }
    }
    let v = (0..n).map(|i| sub(p[i], x[i]).map(|d| d / dt)).collect();
    (p, v)
}
