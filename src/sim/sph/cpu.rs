//! CPU reference in f64 with brute-force neighbours: density, pressure and acceleration
//! by the same formulas as glsl/sph (the fluid's kernel for densities and the pressure
//! force, Mueller's for viscosity and the colour field; self term in density and colour Laplacian; pairs
//! closer than 1e-6 h skip the spiky and viscosity terms; the solid boundary of
//! boundary.rs in the densities and, mirroring p_i, in the pressure force).
use super::boundary::Boundary;
use super::params::{Eos, FluidParams};

pub struct Reference {
    pub density: Vec<f64>,
    pub pressure: Vec<f64>,
    pub acc: Vec<[f64; 3]>,
    /// |grad c| per particle (surface tension acts where it reaches the threshold).
    pub color_grad: Vec<f64>,
}

pub fn pressure(f: &FluidParams, rho: f64) -> f64 {
    let rho0 = f.rest_density as f64;
    let p = match f.eos {
        Eos::Ideal => f.stiffness as f64 * (rho - rho0),
        Eos::Tait => f.eos_constant() as f64 * ((rho / rho0).powf(f.gamma as f64) - 1.0),
    };
    if f.clamp_negative_pressure {
        p.max(0.0)
    } else {
        p
    }
}

pub fn evaluate(f: &FluidParams, b: &Boundary, pos: &[[f32; 4]], vel: &[[f32; 4]]) -> Reference {
    let f = &f.resolved().unwrap_or_else(|_| f.clone());
    let n = pos.len();
    let h = f.h as f64;
    let h2 = h * h;
    let m = f.mass as f64;
    let super::params::Kernels {
        poly6_grad,
        visc_lap,
        ..
    } = super::params::Kernels::new(h);
    let sm = super::kernel::Smoothing::of(f);
    let p3 = |p: &[f32; 4]| [p[0] as f64, p[1] as f64, p[2] as f64];
    let x: Vec<[f64; 3]> = pos.iter().map(p3).collect();
    let v: Vec<[f64; 3]> = vel.iter().map(p3).collect();
    let sub = |a: &[f64; 3], b: &[f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let density: Vec<f64> = (0..n)
        .map(|i| {
            let s: f64 = (0..n).map(|j| sm.w(sub(&x[i], &x[j]))).sum();
            m * s + f.rest_density as f64 * b.solid(h, x[i], [0.0; 3]).rho
        })
        .collect();
    let pressure: Vec<f64> = density.iter().map(|&r| pressure(f, r)).collect();
    let g = [
        f.gravity[0] as f64,
        f.gravity[1] as f64,
        f.gravity[2] as f64,
    ];
    let mut acc = Vec::with_capacity(n);
    let mut color_grad = Vec::with_capacity(n);
    for i in 0..n {
        let mut fp = [0.0; 3];
        let mut fv = [0.0; 3];
        let mut nrm = [0.0; 3];
        let mut lap = m / density[i] * poly6_grad * h2 * 3.0 * h2;
        for j in 0..n {
            if j == i {
                continue;
            }
            let d = sub(&x[i], &x[j]);
            let r2 = dot(&d, &d);
            if r2 >= h2 {
                continue;
            }
            let vol = m / density[j];
            let q = h2 - r2;
            let r = r2.sqrt();
            for k in 0..3 {
                nrm[k] += vol * poly6_grad * q * q * d[k];
            }
            lap += vol * poly6_grad * q * (3.0 * h2 - 7.0 * r2);
            if r > 1e-6 * h {
                let (w, gw) = (h - r, sm.grad(d));
                for k in 0..3 {
                    fp[k] -= vol * 0.5 * (pressure[i] + pressure[j]) * gw[k];
                    fv[k] += vol * (v[j][k] - v[i][k]) * visc_lap * w;
                }
            }
        }
        let gb = b.solid(h, x[i], v[i]).g;
        for k in 0..3 {
            fp[k] -= pressure[i].max(0.0) * gb[k];
        }
        let nl = dot(&nrm, &nrm).sqrt();
        let mut a = [0.0; 3];
        for k in 0..3 {
            let mut fk = fp[k] + f.viscosity as f64 * fv[k] + density[i] * g[k];
            if nl >= f.tension_threshold as f64 {
                fk -= f.surface_tension as f64 * lap * nrm[k] / nl;
            }
            a[k] = fk / density[i];
        }
        acc.push(a);
        color_grad.push(nl);
    }
    Reference {
        density,
        pressure,
        acc,
        color_grad,
    }
}
