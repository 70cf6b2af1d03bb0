//! DFSPH as Bender & Koschier (2017) write it, in f64 with brute-force neighbours, written
//! from the paper's Algorithms 1-3 and not from glsl/sph/dfsph.comp: masses and each
//! particle's own density (kappa_i / rho_i), the factor
//! alpha_i = rho_i / (|sum_j m_j grad W_ij|^2 + sum_j |m_j grad W_ij|^2), the density
//! solve's predicted density rho*_i = rho_i + dt sum_j m_j (v_i - v_j) . grad W_ij (at
//! least rho0: a free surface is not pulled in) and the divergence solve's
//! D rho_i / Dt = sum_j m_j (v_i - v_j) . grad W_ij (at least 0), each iterated with
//! kappa_i = (rho*_i - rho0) alpha_i / dt^2 (divergence: D rho_i / Dt alpha_i / dt) and
//! v_i -= dt sum_j m_j (kappa_i / rho_i + kappa_j / rho_j) grad W_ij until its mean
//! relative error is below `tol`. The boundary enters as Akinci et al.'s (2012) boundary
//! particles do, through their sums (boundary.rs gives them in closed form): psi W in the
//! density, psi grad W in alpha's first sum and in the velocity change with kappa_i /
//! rho_i alone. One step in fluidform's order (the divergence solve of the paper's step
//! end at this step's start): divergence solve, non-pressure forces, predicted velocities,
//! density solve, positions. The kernels are fluidform's (poly6 densities, spiky
//! gradients): the paper leaves W to the user.
use super::boundary::Boundary;
use super::params::{Eos, FluidParams};
use super::v3::{axpy, dot, sub, xyz, Smoothing, V3};

/// What one step did: positions, velocities, and each solve's iterations.
pub struct PaperStep {
    pub pos: Vec<V3>,
    pub vel: Vec<V3>,
    pub iterations: (u32, u32),
}

/// One DFSPH step of `pos`, `vel` (xyz) with each solve iterated to a mean relative error
/// below `tol` (at most 1000 iterations).
pub fn step(
    f: &FluidParams,
    b: &Boundary,
    dt: f64,
    pos: &[[f32; 4]],
    vel: &[[f32; 4]],
    tol: f64,
) -> PaperStep {
    let f = &f.resolved().unwrap_or_else(|_| f.clone());
    let n = pos.len();
    let (h, m, rho0) = (f.h as f64, f.mass as f64, f.rest_density as f64);
    let sm = Smoothing::new(f.kernel(), h);
    let (w, grad) = (|d: V3| sm.w(d), |d: V3| sm.grad(d));
    let x = xyz(pos);
    let mut v = xyz(vel);
    // Boundary particles' sums: psi W = rho0 V_b W, psi grad W (V_b: boundary.rs's volume).
    let solid: Vec<_> = x.iter().map(|xi| b.solid(h, *xi, [0.0; 3])).collect();
    let psi_grad = |i: usize| -> V3 { solid[i].g.map(|c| c * rho0) };
    let rho: Vec<f64> = (0..n)
        .map(|i| m * (0..n).map(|j| w(sub(x[i], x[j]))).sum::<f64>() + rho0 * solid[i].rho)
        .collect();
    let alpha: Vec<f64> = (0..n)
        .map(|i| {
            let (mut s, mut s2) = (psi_grad(i), 0.0);
            for j in (0..n).filter(|&j| j != i) {
                let g = grad(sub(x[i], x[j])).map(|c| c * m);
                s = axpy(1.0, g, s);
                s2 += dot(g, g);
            }
            let d = dot(s, s) + s2;
            if d > 1e-9 {
                rho[i] / d
            } else {
                0.0
            }
        })
        .collect();
    // D rho_i / Dt with the boundary at rest.
    let drho = |v: &[V3], i: usize| -> f64 {
        let mut s = dot(v[i], psi_grad(i));
        for j in (0..n).filter(|&j| j != i) {
            s += m * dot(sub(v[i], v[j]), grad(sub(x[i], x[j])));
        }
        s
    };
    // Iterate one solve: `source` gives each particle's error (>= 0), `scale` turns it
    // into kappa with alpha.
    let solve = |v: &mut Vec<V3>, divergence: bool| -> u32 {
        let err = |v: &[V3], i: usize| -> f64 {
            if divergence {
                drho(v, i).max(0.0)
            } else {
                (rho[i] + dt * drho(v, i)).max(rho0) - rho0
            }
        };
        let relative = |e: &[f64]| -> f64 {
            let scale = if divergence { dt / rho0 } else { 1.0 / rho0 };
            e.iter().sum::<f64>() / n as f64 * scale
        };
        for it in 0..1000u32 {
            let e: Vec<f64> = (0..n).map(|i| err(v, i)).collect();
            if it >= 2 && relative(&e) < tol {
                return it;
            }
            let kappa: Vec<f64> = (0..n)
                .map(|i| e[i] * alpha[i] / if divergence { dt } else { dt * dt })
                .collect();
            let old = v.clone();
            for i in 0..n {
                let mut vi = axpy(-dt * kappa[i] / rho[i], psi_grad(i), old[i]);
                for j in (0..n).filter(|&j| j != i) {
                    let c = m * (kappa[i] / rho[i] + kappa[j] / rho[j]);
                    vi = axpy(-dt * c, grad(sub(x[i], x[j])), vi);
                }
                v[i] = vi;
            }
        }
        1000
    };
    let div_iters = solve(&mut v, true);
    // Non-pressure forces (viscosity, tension, gravity) at the corrected velocities.
    let mut fnp = f.clone();
    fnp.eos = Eos::Ideal;
    fnp.stiffness = 0.0;
    let v4: Vec<[f32; 4]> = v
        .iter()
        .map(|a| [a[0] as f32, a[1] as f32, a[2] as f32, 0.0])
        .collect();
    let a = super::cpu::evaluate(&fnp, b, pos, &v4).acc;
    for i in 0..n {
        v[i] = axpy(dt, a[i], v[i]);
    }
    let density_iters = solve(&mut v, false);
    let pos = (0..n).map(|i| axpy(dt, v[i], x[i])).collect();
    PaperStep {
        pos,
        vel: v,
        iterations: (density_iters, div_iters),
    }
}
