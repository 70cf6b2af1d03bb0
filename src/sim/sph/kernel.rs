//! The smoothing kernels (`--kernel`) in f64, for the GPU's constants and the CPU
//! references alike, with glsl/sph/kernel.glsl the same formulas in f32. One kernel gives
//! a solve both its densities and its pressure gradients, except `muller`, the thesis's
//! pair: poly6 densities with spiky gradients (Mueller 2003, Kelager 2006), whose
//! gradient reads about 0.8 of poly6's density change on a rest lattice.
//! Every kernel's support radius is h (q = r / h):
//!   cubic     W = k (6 q^3 - 6 q^2 + 1) for q <= 1/2, 2 k (1 - q)^3 beyond; k = 8 / (pi h^3)
//!   wendland  W = k (1 - q)^4 (4 q + 1); k = 21 / (2 pi h^3)  (Wendland C2)
//! Their wall terms (boundary.glsl) are the closed-form integrals over a solid half-space
//! at distance d = u h: A(u) = 2 pi int_d^h W r dr (|sum V grad W|) and I(u) = int_d^h A
//! (the solid's density / rho0).
use super::params::FluidParams;
use super::Kernel;
use std::f64::consts::PI;

/// A kernel's support in rest spacings where the fluid sets none (`fluid.support`): there
/// a rest lattice's density is rho0 within 0.1% (cubic: 1.0000 at 2 spacings, the support
/// SPlisHSPlasH uses; Wendland C2 reaches 0.3% only at 3, with about 110 neighbours).
pub fn default_support(k: Kernel) -> Option<f32> {
    match k {
        Kernel::Muller => None,
        Kernel::Cubic => Some(2.0),
        Kernel::Wendland => Some(3.0),
    }
}

/// `KERNEL_MULLER`, ... for glsl/sph/kernel.glsl, one per `Kernel` value.
pub fn defines() -> Vec<(String, String)> {
    Kernel::defines("KERNEL")
}

/// Mueller 2003's kernels' constants: W_poly6 = poly6 (h^2 - r^2)^3, grad W_poly6 =
/// poly6_grad r (h^2 - r^2)^2, grad W_spiky = spiky_grad (h - r)^2 r/|r|, lap W_visc =
/// visc_lap (h - r). Viscosity and the colour field use them whatever `--kernel` says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kernels {
    pub poly6: f64,
    pub poly6_grad: f64,
    pub spiky_grad: f64,
    pub visc_lap: f64,
}

impl Kernels {
    pub fn new(h: f64) -> Self {
        Self {
            poly6: 315.0 / (64.0 * PI * h.powi(9)),
            poly6_grad: -945.0 / (32.0 * PI * h.powi(9)),
            spiky_grad: -45.0 / (PI * h.powi(6)),
            visc_lap: 45.0 / (PI * h.powi(6)),
        }
    }
}

/// The normalisation k of cubic and wendland at support h (0 for muller, whose constants
/// are `Kernels`'s).
pub fn norm(kind: Kernel, h: f64) -> f64 {
    match kind {
        Kernel::Muller => 0.0,
        Kernel::Cubic => 8.0 / (PI * h.powi(3)),
        Kernel::Wendland => 21.0 / (2.0 * PI * h.powi(3)),
    }
}

/// A kernel at support h: W and grad W in f64.
#[derive(Clone, Copy, Debug)]
pub struct Smoothing {
    pub kind: Kernel,
    h: f64,
    k: Kernels,
    norm: f64,
}

impl Smoothing {
    pub fn new(kind: Kernel, h: f64) -> Self {
        Self {
            kind,
            h,
            k: Kernels::new(h),
            norm: norm(kind, h),
        }
    }

    /// The fluid's kernel at its support.
    pub fn of(f: &FluidParams) -> Self {
        Self::new(f.kernel(), f.h as f64)
    }

    /// W(d).
    pub fn w(&self, d: [f64; 3]) -> f64 {
        self.w_r2(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    }

    /// W at squared distance r2.
    pub fn w_r2(&self, r2: f64) -> f64 {
        let h = self.h;
        if r2 >= h * h {
            return 0.0;
        }
        let q = r2.sqrt() / h;
        match self.kind {
            Kernel::Muller => self.k.poly6 * (h * h - r2).powi(3),
            Kernel::Cubic if q <= 0.5 => self.norm * (6.0 * q * q * (q - 1.0) + 1.0),
            Kernel::Cubic => self.norm * 2.0 * (1.0 - q).powi(3),
            Kernel::Wendland => self.norm * (1.0 - q).powi(4) * (4.0 * q + 1.0),
        }
    }

    /// dW/dr / r at distance r < h (muller: spiky's), so grad W(d) = d times it.
    pub fn dw_over_r(&self, r: f64) -> f64 {
        let (h, q) = (self.h, r / self.h);
        match self.kind {
            Kernel::Muller => self.k.spiky_grad * (h - r) * (h - r) / r,
            Kernel::Cubic if q <= 0.5 => 6.0 * self.norm / (h * h) * (3.0 * q - 2.0),
            Kernel::Cubic => -6.0 * self.norm / (h * r) * (1.0 - q).powi(2),
            Kernel::Wendland => -20.0 * self.norm / (h * h) * (1.0 - q).powi(3),
        }
    }

    /// grad W(d) (0 past h and, as the shaders, where |d| <= 1e-6 h).
    pub fn grad(&self, d: [f64; 3]) -> [f64; 3] {
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if r >= self.h || r <= 1e-6 * self.h {
            return [0.0; 3];
        }
        let s = self.dw_over_r(r);
        [s * d[0], s * d[1], s * d[2]]
    }
}

/// The density / rho0 a solid half-space adds at distance d (u = d / h clamped to 0..1).
pub fn wall_density(kind: Kernel, h: f64, d: f64) -> f64 {
    let u = (d / h).clamp(0.0, 1.0);
    let w = 1.0 - u;
    match kind {
        Kernel::Muller => {
            let f = u - 4.0 / 3.0 * u.powi(3) + 6.0 / 5.0 * u.powi(5) - 4.0 / 7.0 * u.powi(7)
                + u.powi(9) / 9.0;
            0.5 - 315.0 / 256.0 * f
        }
        Kernel::Cubic if u <= 0.5 => {
            0.5 - 7.0 / 5.0 * u + 8.0 / 3.0 * u.powi(3) - 24.0 / 5.0 * u.powi(5)
                + 16.0 / 5.0 * u.powi(6)
        }
        Kernel::Cubic => 8.0 / 15.0 * w.powi(5) * (2.0 * u + 1.0),
        Kernel::Wendland => 0.5 * w.powi(6) * (3.0 * u * u + 3.0 * u + 1.0),
    }
}

/// |sum V grad W| of a solid half-space at distance d (muller: spiky's gradient).
pub fn wall_push(kind: Kernel, h: f64, d: f64) -> f64 {
    let u = (d / h).clamp(0.0, 1.0);
    let w = 1.0 - u;
    let a = match kind {
        Kernel::Muller => 30.0 * (w.powi(4) / 4.0 - w.powi(5) / 5.0),
        Kernel::Cubic if u <= 0.5 => 1.4 - 8.0 * u * u + 24.0 * u.powi(4) - 19.2 * u.powi(5),
        Kernel::Cubic => 1.6 * w.powi(4) * (4.0 * u + 1.0),
        Kernel::Wendland => 1.5 * w.powi(5) * (8.0 * u * u + 5.0 * u + 1.0),
    };
    a / h
}

/// The points of a cubic lattice at the rest spacing within h of a lattice point (itself
/// included), as offsets.
pub fn lattice(f: &FluidParams) -> Vec<[f64; 3]> {
    let (h, s) = (f.h as f64, f.spacing() as f64);
    let r = (h / s).ceil() as i32;
    let mut out = Vec::new();
    for a in -r..=r {
        for b in -r..=r {
            for c in -r..=r {
                let d = [a as f64 * s, b as f64 * s, c as f64 * s];
                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < h * h {
                    out.push(d);
                }
            }
        }
    }
    out
}

/// The density / rho0 of a rest lattice, self included, by the fluid's kernel.
pub fn lattice_density(f: &FluidParams) -> f64 {
    let sm = Smoothing::of(f);
    let m = f.mass as f64 / f.rest_density as f64;
    lattice(f).iter().map(|d| m * sm.w(*d)).sum()
}

/// sum_j |V grad W(x_i - x_j)|^2 over a rest lattice (V = m / rho0), by the fluid's
/// kernel: the pressure solvers' prototype particle.
pub fn proto_grad2(f: &FluidParams) -> f64 {
    let sm = Smoothing::of(f);
    let v = f.mass as f64 / f.rest_density as f64;
    lattice(f)
        .iter()
        .map(|d| {
            let g = sm.grad(*d);
            v * v * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2])
        })
        .sum()
}

/// The neighbours of a rest lattice point (itself excluded).
pub fn lattice_neighbours(f: &FluidParams) -> usize {
    lattice(f).len() - 1
}

/// How much farther the walls' terms (boundary.glsl) take a particle to be than it is: the
/// offset at which a rest lattice whose first layer rests at the collision margin (half
/// a spacing) reads, in that layer, the density an interior particle reads. Without it
/// the continuum wall is denser than the lattice it stands for (cubic at 2 spacings:
/// +3.8% of rho0 in the first layer), so a fluid at rest next to a wall starts compressed.
pub fn wall_offset(f: &FluidParams) -> f64 {
    let (h, s) = (f.h as f64, f.spacing() as f64);
    let sm = Smoothing::of(f);
    let m = f.mass as f64 / f.rest_density as f64;
    // The first layer's fluid sum: the lattice on its side of the wall (z >= 0).
    let fluid: f64 = lattice(f)
        .iter()
        .filter(|d| d[2] >= -1e-9 * s)
        .map(|d| m * sm.w(*d))
        .sum();
    let want = lattice_density(f) - fluid;
    let kind = f.kernel();
    // wall_density falls with the distance: bisect the offset in (-s / 2, h).
    let (mut lo, mut hi) = (-0.5 * s, h);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        match wall_density(kind, h, 0.5 * s + mid) > want {
            true => lo = mid,
            false => hi = mid,
        }
    }
    0.5 * (lo + hi)
}
