//! CPU reference ray marcher: fixed steps on the grid t = k * step through the metaballs'
//! bounds until the field reaches the threshold, `refine` bisection steps on the hit,
//! normal = -grad / |grad|.
use crate::render::DensityFn;
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct MarchParams {
    pub density: DensityFn,
    pub radius: f32,
    pub threshold: f32,
    pub step: f32,
    pub max_steps: u32,
    pub refine: u32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the surface point.
    pub t: f32,
    pub point: Vec3,
    /// Outward unit normal.
    pub normal: Vec3,
}

/// Sum of D(|x - c_i|) over all metaballs.
pub fn field(centers: &[Vec3], p: &MarchParams, x: Vec3) -> f32 {
    centers
        .iter()
        .map(|c| p.density.value((x - *c).length(), p.radius))
        .sum()
}

/// Gradient of the field.
pub fn gradient(centers: &[Vec3], p: &MarchParams, x: Vec3) -> Vec3 {
    let mut g = Vec3::ZERO;
    for c in centers {
        let d = x - *c;
        let r = d.length();
        if r > 1e-12 && r < p.radius {
            g += d / r * p.density.derivative(r, p.radius);
        }
    }
    g
}

/// The interval [t0, t1] where the ray meets the box [lo, hi], if any.
pub fn ray_box(origin: Vec3, dir: Vec3, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
    let inv = dir.recip();
    let a = (lo - origin) * inv;
    let b = (hi - origin) * inv;
    let t0 = a.min(b).max_element().max(0.0);
    let t1 = a.max(b).min_element();
    (t0 <= t1).then_some((t0, t1))
}

/// March the ray (unit `dir`) through the box of the metaballs grown by R.
pub fn march(centers: &[Vec3], p: &MarchParams, origin: Vec3, dir: Vec3) -> Option<Hit> {
    march_counted(centers, p, origin, dir).0
}

/// `march` and the samples it took, refinement included (march.comp's step counter).
pub fn march_counted(
    centers: &[Vec3],
    p: &MarchParams,
    origin: Vec3,
    dir: Vec3,
) -> (Option<Hit>, u32) {
    let mut steps = 0;
    let hit = march_inner(centers, p, origin, dir, &mut steps);
    (hit, steps)
}

fn march_inner(
    centers: &[Vec3],
    p: &MarchParams,
    origin: Vec3,
    dir: Vec3,
    steps: &mut u32,
) -> Option<Hit> {
    if centers.is_empty() {
        return None;
    }
    let lo = centers.iter().fold(Vec3::splat(f32::MAX), |a, c| a.min(*c)) - Vec3::splat(p.radius);
    let hi = centers.iter().fold(Vec3::splat(f32::MIN), |a, c| a.max(*c)) + Vec3::splat(p.radius);
    let (t0, t1) = ray_box(origin, dir, lo, hi)?;
    // Samples on the grid t = k * step, as glsl/render/metaball/march.comp.
    let mut t = (t0 / p.step).ceil() * p.step;
    let mut prev = (t - p.step).max(0.0);
    for _ in 0..p.max_steps {
        if t > t1 {
            return None;
        }
        *steps += 1;
        if field(centers, p, origin + dir * t) >= p.threshold {
            // Bisection between the last outside sample and this inside one.
            let (mut a, mut b) = (prev, t);
            for _ in 0..p.refine {
                *steps += 1;
                let m = 0.5 * (a + b);
                if field(centers, p, origin + dir * m) >= p.threshold {
                    b = m;
                } else {
                    a = m;
                }
            }
            let point = origin + dir * b;
            let g = gradient(centers, p, point);
            return Some(Hit {
                t: b,
                point,
                normal: (-g).normalize_or_zero(),
            });
        }
        prev = t;
        t += p.step;
    }
    None
}
