//! The solid boundary of the CPU references in f64, as glsl/sph/boundary.glsl: the domain's
//! walls and the colliders as solid half-spaces at rest density (their density / rho0 and
//! sum V grad W in closed form), and common.glsl's collision response.
use super::collider::{Collider, GpuCollider};
use super::kernel::{wall_density, wall_push};
use super::params::FluidParams;
use super::Kernel;
use crate::error::Result;

pub use super::v3::V3;
use super::v3::{axpy, dot};

fn v3(a: [f32; 4]) -> V3 {
    [a[0] as f64, a[1] as f64, a[2] as f64]
}

/// The domain box (min, max corners) and the colliders, with the response's restitution
/// and friction.
pub struct Boundary {
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub colliders: Vec<GpuCollider>,
    pub restitution: f32,
    pub friction: f32,
    /// The response keeps particles this far from every surface: half the rest spacing.
    pub margin: f64,
    /// The kernel whose wall terms the densities and gradients take, and their offset
    /// (`kernel::wall_offset`).
    pub kernel: Kernel,
    pub offset: f64,
}

/// The boundary as a particle at x moving with v sees it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Solid {
    /// Density / rho0.
    pub rho: f64,
    /// sum_b V grad W (V = m / rho0).
    pub g: V3,
    /// sum_b V (v - v_b) . grad W.
    pub rate: f64,
}

impl Boundary {
    /// The domain box alone.
    pub fn new(f: &FluidParams, min: [f32; 3], max: [f32; 3]) -> Self {
        let f = &f.resolved().unwrap_or_else(|_| f.clone());
        Self {
            min,
            max,
            colliders: Vec::new(),
            restitution: f.restitution,
            friction: f.friction,
            margin: 0.5 * f.spacing() as f64,
            kernel: f.kernel(),
            offset: super::kernel::wall_offset(f),
        }
    }

    /// The box and `colliders` (as the GPU gets them; a malformed one is an error).
    pub fn with_colliders(mut self, colliders: &[Collider]) -> Result<Self> {
        self.colliders = colliders
            .iter()
            .map(|c| c.to_gpu())
            .collect::<Result<_>>()?;
        Ok(self)
    }

    /// Each collider's nearest surface normal (into the fluid), signed distance and velocity.
    fn collider_planes(&self, x: V3) -> impl Iterator<Item = (V3, f64, V3)> + '_ {
        self.colliders.iter().map(move |c| {
            let (a, b) = (v3(c.a), v3(c.b));
            if c.b[3] == 0.0 {
                (a, dot(a, x) - c.a[3] as f64, v3(c.vel))
            } else {
                let mut q = a;
                if c.b[3] == 2.0 {
                    let ab = axpy(-1.0, a, b);
                    let t = (dot(axpy(-1.0, a, x), ab) / dot(ab, ab).max(1e-20)).clamp(0.0, 1.0);
                    q = axpy(t, ab, a);
                }
                let r = axpy(-1.0, q, x);
                let len = dot(r, r).sqrt();
                let n = if len > 1e-12 {
                    r.map(|c| c / len)
                } else {
                    [0.0, 1.0, 0.0]
                };
                (n, len - c.a[3] as f64, v3(c.vel))
            }
        })
    }

    /// The boundary at x for a particle moving with v: the box's walls and the nearest
    /// collider surface united as 1 - prod(1 - I_k) (boundary.glsl says why).
    pub fn solid(&self, h: f64, x: V3, v: V3) -> Solid {
        let mut near: Vec<(V3, f64, V3)> = Vec::new();
        for k in 0..3 {
            let mut n = [0.0; 3];
            n[k] = 1.0;
            near.push((n, x[k] - self.min[k] as f64, [0.0; 3]));
            n[k] = -1.0;
            near.push((n, self.max[k] as f64 - x[k], [0.0; 3]));
        }
        // Of the colliders only the nearest surface counts; a sphere or capsule thinner
        // than h acts by the response alone (boundary.glsl).
        let nearest = self
            .colliders
            .iter()
            .zip(self.collider_planes(x))
            .filter(|(c, _)| c.b[3] == 0.0 || c.a[3] as f64 >= h)
            .map(|(_, p)| p)
            .fold(None::<(V3, f64, V3)>, |best, p| match best {
                Some(b) if b.1 <= p.1 => Some(b),
                _ => Some(p),
            });
        near.extend(nearest);
        near.retain(|p| p.1 + self.offset < h);
        let terms: Vec<(f64, f64)> = near
            .iter()
            .map(|p| {
                let d = p.1 + self.offset;
                (
                    wall_density(self.kernel, h, d),
                    wall_push(self.kernel, h, d),
                )
            })
            .collect();
        let keep: f64 = terms.iter().map(|t| 1.0 - t.0).product();
        let mut s = Solid {
            rho: 1.0 - keep,
            ..Default::default()
        };
        for ((n, _, vb), (i, a)) in near.iter().zip(&terms) {
            let a = a * keep / (1.0 - i);
            s.g = axpy(-a, *n, s.g);
            s.rate -= a * dot(axpy(-1.0, *vb, v), *n);
        }
        s
    }

    /// v's part into the surface (normal n, moving with vb) reflected with restitution,
    /// its tangent damped.
    fn respond(&self, v: V3, n: V3, vb: V3) -> V3 {
        let rel = axpy(-1.0, vb, v);
        let vn = dot(rel, n);
        if vn >= 0.0 {
            return v;
        }
        let vt = axpy(-vn, n, rel);
        let out = axpy(1.0 - self.friction as f64, vt, vb);
        axpy(-(self.restitution as f64) * vn, n, out)
    }

    /// common.glsl's `collide`: x pushed out of the colliders to `margin` from their
    /// surface, then clamped to the box less `margin`; v answered at each.
    pub fn collide(&self, x: &mut V3, v: &mut V3) {
        let r = self.margin;
        for c in 0..self.colliders.len() {
            let (n, d, vb) = self.collider_planes(*x).nth(c).expect("collider");
            if d < r {
                *x = axpy(r - d, n, *x);
                *v = self.respond(*v, n, vb);
            }
        }
        for k in 0..3 {
            let (lo, hi) = (self.min[k] as f64, self.max[k] as f64);
            let m = r.min(0.5 * (hi - lo));
            let mut n = [0.0; 3];
            n[k] = 1.0;
            if x[k] < lo + m {
                x[k] = lo + m;
                *v = self.respond(*v, n, [0.0; 3]);
            }
            n[k] = -1.0;
            if x[k] > hi - m {
                x[k] = hi - m;
                *v = self.respond(*v, n, [0.0; 3]);
            }
        }
    }

    /// The velocity the response leaves to a particle at x moving with v for dt.
    pub fn response(&self, x: V3, dt: f64, v: V3) -> V3 {
        let (mut y, mut v) = (axpy(dt, v, x), v);
        self.collide(&mut y, &mut v);
        v
    }
}
