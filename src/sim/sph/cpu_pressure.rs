//! CPU reference in f64 of one step of the incompressible solvers, brute-force neighbours,
//! by the formulas of glsl/sph/{pcisph,dfsph,pbf}.comp, with a fixed iteration count,
//! the solid boundary (boundary.rs) in the densities and solves and the collision
//! response where the shaders apply it (DFSPH: once, after the positions). Starts from a state with no warm-start stiffness
//! (a scene's first step).
use super::boundary::{Boundary, Solid};
use super::params::{Eos, FluidParams};
use super::v3::{axpy, cross, dot, sub, xyz, Smoothing, V3};
use crate::sph::Solver;

struct K {
    h: f64,
    sm: Smoothing,
    v: f64,
    rho0: f64,
    m: f64,
}

impl K {
    fn w(&self, r2: f64) -> f64 {
        self.sm.w_r2(r2)
    }
    /// V grad W_spiky (zero past h or at r ~ 0).
    fn vg(&self, d: V3) -> V3 {
        self.sm.grad(d).map(|c| self.v * c)
    }
    /// The fluid's density at x_i (the boundary's is added by the callers).
    fn density(&self, x: &[V3], i: usize) -> f64 {
        self.m
            * x.iter()
                .map(|y| self.w(dot(sub(x[i], *y), sub(x[i], *y))))
                .sum::<f64>()
    }
    /// (sum V grad W, sum |V grad W|^2) at x_i.
    fn grad_sums(&self, x: &[V3], i: usize) -> (V3, f64) {
        let (mut sg, mut s2) = ([0.0; 3], 0.0);
        for (j, y) in x.iter().enumerate() {
            if j != i {
                let g = self.vg(sub(x[i], *y));
                sg = axpy(1.0, g, sg);
                s2 += dot(g, g);
            }
        }
        (sg, s2)
    }
    /// (|sum V grad W + g_b|^2 + sum |V grad W|^2) at x_i, g_b the boundary's sum (it
    /// does not move: no square of its own).
    fn grad2(&self, x: &[V3], i: usize, gb: V3) -> f64 {
        let (sg, s2) = self.grad_sums(x, i);
        let sg = axpy(1.0, gb, sg);
        dot(sg, sg) + s2
    }
}

/// Positions and velocities after one step of `f.solver` with `iterations` per solve.
pub fn step(
    f: &FluidParams,
    b: &Boundary,
    dt: f64,
    pos: &[[f32; 4]],
    vel: &[[f32; 4]],
    iterations: u32,
) -> (Vec<V3>, Vec<V3>) {
    let f = &f.resolved().unwrap_or_else(|_| f.clone());
    let n = pos.len();
    let kk = K {
        h: f.h as f64,
        sm: Smoothing::of(f),
        v: f.mass as f64 / f.rest_density as f64,
        rho0: f.rest_density as f64,
        m: f.mass as f64,
    };
    let proto = super::params::proto_grad2(f);
    let x = xyz(pos);
    let v = xyz(vel);
    let rho: Vec<f64> = (0..n)
        .map(|i| kk.density(&x, i) + kk.rho0 * b.solid(kk.h, x[i], [0.0; 3]).rho)
        .collect();
    // Non-pressure accelerations (the forces pass with no equation of state).
    let mut fnp = f.clone();
    fnp.eos = Eos::Ideal;
    fnp.stiffness = 0.0;
    if f.solver == Solver::Pbf {
        fnp.viscosity = 0.0;
    }
    let f32s = |a: &[V3]| -> Vec<[f32; 4]> {
        a.iter()
            .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32, 0.0])
            .collect()
    };
    let a_np = |v: &[V3]| super::cpu::evaluate(&fnp, b, pos, &f32s(v)).acc;
    let c = Common {
        kk: &kk,
        b,
        proto,
        dt,
        iterations,
        min_neighbors: super::params::SphGpuParams::new(f, [0.0; 3], [0.0; 3], 0.0, 0)
            .min_neighbors,
    };
    match f.solver {
        Solver::Wcsph => panic!("cpu_pressure covers the incompressible solvers"),
        Solver::Pcisph => {
            let a = a_np(&v);
            pcisph(&c, x, v, &a)
        }
        Solver::Dfsph => dfsph(&c, x, v, &rho, &a_np),
        Solver::Pbf => {
            let a = a_np(&v);
            pbf(&c, f, x, v, &a)
        }
    }
}

/// What every solver's step shares: kernels, the boundary, the prototype's gradient sum,
/// dt, iterations.
struct Common<'a> {
    kk: &'a K,
    b: &'a Boundary,
    proto: f64,
    dt: f64,
    iterations: u32,
    /// DFSPH's divergence solve leaves out particles with fewer fluid neighbours.
    min_neighbors: u32,
}

/// PCISPH: pressures predicted and corrected on the predicted positions (collided); delta
/// from the fluid's gradients alone.
fn pcisph(c: &Common, x: Vec<V3>, v: Vec<V3>, a: &[V3]) -> (Vec<V3>, Vec<V3>) {
    let (kk, b, dt, n) = (c.kk, c.b, c.dt, x.len());
    let at = |x: V3| b.solid(kk.h, x, [0.0; 3]);
    let delta: Vec<f64> = (0..n)
        .map(|i| 0.5 / (2.0 * dt * dt * kk.grad2(&x, i, [0.0; 3]).max(1e-3 * c.proto)))
        .collect();
    let cap = 0.2 / (2.0 * dt * dt * c.proto);
    let mut p = vec![0.0; n];
    let mut ap = vec![[0.0; 3]; n];
    for _ in 0..c.iterations {
        let xs: Vec<V3> = (0..n)
            .map(|i| {
                let vi = axpy(dt, axpy(1.0, a[i], ap[i]), v[i]);
                let (mut y, mut vy) = (axpy(dt, vi, x[i]), vi);
                b.collide(&mut y, &mut vy);
                y
            })
            .collect();
        let solid: Vec<Solid> = xs.iter().map(|y| at(*y)).collect();
        for i in 0..n {
            let err = kk.density(&xs, i) / kk.rho0 + solid[i].rho - 1.0;
            p[i] = (p[i] + delta[i] * err).clamp(0.0, cap);
        }
        for i in 0..n {
            let mut s = [0.0; 3];
            for j in 0..n {
                if j != i {
                    s = axpy(-(p[i] + p[j]), kk.vg(sub(xs[i], xs[j])), s);
                }
            }
            ap[i] = axpy(-p[i], solid[i].g, s);
        }
    }
    let mut v: Vec<V3> = (0..n)
        .map(|i| axpy(dt, axpy(1.0, a[i], ap[i]), v[i]))
        .collect();
    let mut x: Vec<V3> = (0..n).map(|i| axpy(dt, v[i], x[i])).collect();
    for i in 0..n {
        b.collide(&mut x[i], &mut v[i]);
    }
    (x, v)
}

/// DFSPH: the divergence solve, non-pressure forces, the density solve, then the move.
fn dfsph(
    c: &Common,
    x: Vec<V3>,
    mut v: Vec<V3>,
    rho: &[f64],
    a_np: &dyn Fn(&[V3]) -> Vec<V3>,
) -> (Vec<V3>, Vec<V3>) {
    let (kk, walls, dt, n) = (c.kk, c.b, c.dt, x.len());
    let solid = |i: usize, v: V3| walls.solid(kk.h, x[i], v);
    // The boundary's sum V grad W (positions stay put through both solves).
    let gb: Vec<V3> = (0..n).map(|i| solid(i, [0.0; 3]).g).collect();
    let alpha: Vec<f64> = (0..n)
        .map(|i| {
            let d = kk.grad2(&x, i, gb[i]);
            if d > 1e-3 * c.proto {
                1.0 / d
            } else {
                0.0
            }
        })
        .collect();
    let rate = |v: &[V3], i: usize| -> f64 {
        solid(i, v[i]).rate
            + (0..n)
                .filter(|&j| j != i)
                .map(|j| dot(sub(v[i], v[j]), kk.vg(sub(x[i], x[j]))))
                .sum::<f64>()
    };
    // Fluid neighbours: fewer than min_neighbors, and the divergence solve leaves it out.
    let sparse: Vec<bool> = (0..n)
        .map(|i| {
            let near = (0..n)
                .filter(|&j| j != i && dot(sub(x[i], x[j]), sub(x[i], x[j])) < kk.h * kk.h)
                .count();
            near < c.min_neighbors as usize
        })
        .collect();
    // Projected Jacobi on the signed residual, from no stiffness (a first step).
    let solve = |v: &mut Vec<V3>, divergence: bool| {
        let residual = |v: &[V3], i: usize| match divergence {
            true if sparse[i] => 0.0,
            true => rate(v, i),
            false => rho[i] / kk.rho0 + dt * rate(v, i) - 1.0,
        };
        let scale = if divergence { dt } else { dt * dt };
        let mut kappa = vec![0.0; n];
        for _ in 0..c.iterations {
            let k: Vec<f64> = (0..n)
                .map(|i| (kappa[i] + 0.5 * residual(v, i) * alpha[i] / scale).max(0.0) - kappa[i])
                .collect();
            let old = v.clone();
            for i in 0..n {
                let mut vi = axpy(-dt * k[i], gb[i], old[i]);
                for j in 0..n {
                    if j != i {
                        vi = axpy(-dt * (k[i] + k[j]), kk.vg(sub(x[i], x[j])), vi);
                    }
                }
                v[i] = vi;
                kappa[i] += k[i];
            }
        }
    };
    solve(&mut v, true);
    let a = a_np(&v);
    for i in 0..n {
        v[i] = axpy(dt, a[i], v[i]);
    }
    solve(&mut v, false);
    let mut x: Vec<V3> = (0..n).map(|i| axpy(dt, v[i], x[i])).collect();
    for i in 0..n {
        walls.collide(&mut x[i], &mut v[i]);
    }
    (x, v)
}

/// PBF: density constraints solved on predicted positions (collided), then XSPH and
/// vorticity.
fn pbf(c: &Common, f: &FluidParams, x: Vec<V3>, v: Vec<V3>, a: &[V3]) -> (Vec<V3>, Vec<V3>) {
    let (kk, b, dt, n) = (c.kk, c.b, c.dt, x.len());
    let collided = |mut y: V3| {
        let mut vy = [0.0; 3];
        b.collide(&mut y, &mut vy);
        y
    };
    let mut xs: Vec<V3> = (0..n)
        .map(|i| collided(axpy(dt, axpy(dt, a[i], v[i]), x[i])))
        .collect();
    let dq = f.pbf.scorr_dq as f64 * kk.h;
    let wdq = kk.w(dq * dq);
    for _ in 0..c.iterations {
        let solid: Vec<Solid> = xs.iter().map(|y| b.solid(kk.h, *y, [0.0; 3])).collect();
        let lambda: Vec<f64> = (0..n)
            .map(|i| {
                let cst = (kk.density(&xs, i) / kk.rho0 + solid[i].rho - 1.0).max(0.0);
                -cst / (kk.grad2(&xs, i, solid[i].g) + f.pbf.relaxation as f64 * c.proto)
            })
            .collect();
        let dx: Vec<V3> = (0..n)
            .map(|i| {
                let mut s = axpy(lambda[i], solid[i].g, [0.0; 3]);
                for j in 0..n {
                    let d = sub(xs[i], xs[j]);
                    if j != i && dot(d, d) < kk.h * kk.h {
                        let sc = -f.pbf.scorr_k as f64
                            * (kk.w(dot(d, d)) / wdq).powf(f.pbf.scorr_n as f64)
                            / c.proto;
                        s = axpy(lambda[i] + lambda[j] + sc, kk.vg(d), s);
                    }
                }
                s
            })
            .collect();
        for i in 0..n {
            xs[i] = collided(axpy(1.0, dx[i], xs[i]));
        }
    }
    let v: Vec<V3> = (0..n)
        .map(|i| axpy(-1.0, x[i], xs[i]).map(|c| c / dt))
        .collect();
    let v = pbf_velocity(kk, f, dt, &xs, v);
    (xs, v)
}

/// PBF's velocity update: XSPH viscosity and vorticity confinement.
fn pbf_velocity(kk: &K, f: &FluidParams, dt: f64, x: &[V3], mut v: Vec<V3>) -> Vec<V3> {
    let n = x.len();
    let mut w = vec![[0.0; 3]; n];
    let mut dv = vec![[0.0; 3]; n];
    for i in 0..n {
        for j in 0..n {
            let d = sub(x[i], x[j]);
            if j != i && dot(d, d) < kk.h * kk.h {
                let vji = sub(v[j], v[i]);
                w[i] = axpy(1.0, cross(kk.vg(d), vji), w[i]);
                dv[i] = axpy(kk.v * kk.w(dot(d, d)) * f.pbf.xsph as f64, vji, dv[i]);
            }
        }
    }
    for i in 0..n {
        let wl = dot(w[i], w[i]).sqrt();
        let mut eta = [0.0; 3];
        for j in 0..n {
            if j != i {
                let wj = dot(w[j], w[j]).sqrt();
                eta = axpy(wj - wl, kk.vg(sub(x[i], x[j])), eta);
            }
        }
        let el = dot(eta, eta).sqrt();
        let fv = if el > 1e-6 / kk.h {
            cross(eta.map(|c| c / el), w[i]).map(|c| c * f.pbf.vorticity as f64)
        } else {
            [0.0; 3]
        };
        v[i] = axpy(1.0, dv[i], axpy(dt, fv, v[i]));
    }
    v
}
