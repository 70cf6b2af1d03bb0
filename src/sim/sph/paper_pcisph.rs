//! PCISPH as Solenthaler & Pajarola (2009) write it (their Algorithm 1), in f64 with
//! brute-force neighbours, written from the paper and not from glsl/sph/pcisph.comp:
//! neighbours N_i(t) found once at the step's start, pressures and pressure forces from 0,
//! then until the mean density error is below `tol` (and at least 3 times, the paper's
//! minimum): predicted velocities v*_i = v_i + dt (F_ext + F_p) / m and positions
//! x*_i = x_i + dt v*_i, predicted densities rho*_i = sum_j m W(x*_i - x*_j), pressures
//! p_i += delta (rho*_i - rho0), and pressure forces
//! F_p,i = -m^2 sum_j (p_i / rho0^2 + p_j / rho0^2) grad W(x*_i - x*_j); the step's
//! velocities and positions then take the last F_p. delta is the paper's, from one
//! prototype particle with a filled neighbourhood (a simple cubic lattice at the rest
//! spacing, `params::proto_grad2`): delta = -1 / (beta (-|sum grad W|^2 - sum |grad W|^2)),
//! beta = 2 (dt m / rho0)^2. Three choices the paper leaves open: the loop stops on the
//! mean density error (our solvers' rule; the paper tests rho*_err against eta, which may
//! be read per particle), pressures stay at least 0 (a free surface is not pulled in; the
//! error counts compression only), and the pressure
//! force's gradients are taken at the predicted positions, where the loop has just put the
//! particles. Kernels are fluidform's (poly6 densities, spiky gradients): the paper leaves
//! W to the user. No boundary: a comparison keeps the particles off the walls.
use super::params::FluidParams;
use super::v3::{axpy, neighbours, sub, xyz, Smoothing, V3};

/// One PCISPH step of `pos`, `vel` (xyz) under `accel` (F_ext / m) iterated to a mean
/// relative density error below `tol` (at most 1000 iterations): the positions and
/// velocities after it, and the iterations taken. `omega` scales delta (1: the paper's;
/// the converged step does not depend on it, only whether and how fast it converges: on a
/// compressed lattice the paper's delta overshoots, as neighbours' pressures that
/// alternate push twice as hard as the prototype's uniform ones).
pub fn step(
    f: &FluidParams,
    dt: f64,
    accel: V3,
    pos: &[[f32; 4]],
    vel: &[[f32; 4]],
    tol: f64,
    omega: f64,
) -> (Vec<V3>, Vec<V3>, u32) {
    let f = &f.resolved().unwrap_or_else(|_| f.clone());
    let n = pos.len();
    let (h, m, rho0) = (f.h as f64, f.mass as f64, f.rest_density as f64);
    let sm = Smoothing::new(f.kernel(), h);
    let (w, grad) = (|d: V3| sm.w(d), |d: V3| sm.grad(d));
    // The prototype's sum |grad W|^2 (its sum grad W vanishes): proto_grad2 is it times
    // (m / rho0)^2.
    let grad2 = super::params::proto_grad2(f) * (rho0 / m).powi(2);
    let beta = 2.0 * (dt * m / rho0).powi(2);
    let delta = omega / (beta * grad2);
    let x = xyz(pos);
    let v = xyz(vel);
    let nb = neighbours(&x, h);
    let predict = |a_p: &[V3]| -> (Vec<V3>, Vec<V3>) {
        let vs: Vec<V3> = (0..n)
            .map(|i| axpy(dt, axpy(1.0, a_p[i], accel), v[i]))
            .collect();
        let xs = (0..n).map(|i| axpy(dt, vs[i], x[i])).collect();
        (xs, vs)
    };
    let mut p = vec![0.0f64; n];
    let mut a_p = vec![[0.0f64; 3]; n];
    let mut iterations = 0u32;
    loop {
        let (xs, _) = predict(&a_p);
        let mut error = 0.0;
        for i in 0..n {
            let rho = m * (w([0.0; 3]) + nb[i].iter().map(|&j| w(sub(xs[i], xs[j]))).sum::<f64>());
            p[i] = (p[i] + delta * (rho - rho0)).max(0.0);
            error += (rho / rho0 - 1.0).max(0.0);
        }
        a_p = (0..n)
            .map(|i| {
                nb[i].iter().fold([0.0; 3], |acc, &j| {
                    let s = -m * (p[i] + p[j]) / (rho0 * rho0);
                    axpy(s, grad(sub(xs[i], xs[j])), acc)
                })
            })
            .collect();
        iterations += 1;
        if (iterations >= 3 && error / n as f64 <= tol) || iterations >= 1000 {
            break;
        }
    }
    let (xs, vs) = predict(&a_p);
    (xs, vs, iterations)
}
