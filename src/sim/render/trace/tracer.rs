//! The reference tracer: spheres, a camera as the renderer's (Vulkan clip space, y down),
//! a material per scene, recursion to depth D exactly as the thesis defines it (a path
//! that would go deeper reads the environment instead). Output: RGBA8, gamma 2.2.
use super::env::{sun, Env};
use super::optics::{conductor_f0, fresnel_dielectric, reflect, refract, schlick};
use crate::render::Camera;
use crate::render::DensityFn;
use glam::DVec3;

#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    pub center: DVec3,
    pub radius: f64,
}

/// A material, with its constants.
#[derive(Clone, Copy, Debug)]
pub enum Look {
    /// Blinn-Phong lit by the sun: base * (0.15 + 0.85 max(n.l, 0)) + 0.6 max(n.h, 0)^64.
    Phong { base: DVec3 },
    /// A dielectric of index `ior` absorbing `sigma` per metre inside (0: clear glass).
    Dielectric { ior: f64, sigma: DVec3 },
    /// A conductor of complex index n + ik per channel.
    Conductor { n: DVec3, k: DVec3 },
}

pub struct Reference {
    pub spheres: Vec<Sphere>,
    pub look: Look,
    /// Recursion depth D.
    pub depth: u32,
    pub env: Env,
    /// The radius of curvature the ray cones assume at a surface (the renderer's
    /// metaball radius R): a cone's spread grows by width / this per refraction, twice
    /// that per reflection.
    pub cone_radius: f64,
}

/// The radius at which `k` coincident metaballs of `density`, radius `r`, sum to `t`
/// (PAPERS.md section 4's formulas, q = r/R): the surface of one metaball is that sphere.
pub fn iso_radius(density: DensityFn, r: f64, t: f64, k: f64) -> Option<f64> {
    let d = |q: f64| -> f64 {
        let q2 = q * q;
        match density {
            DensityFn::Wyvill => {
                1.0 - 4.0 / 9.0 * q2.powi(3) + 17.0 / 9.0 * q2 * q2 - 22.0 / 9.0 * q2
            }
            DensityFn::Nishimura if q <= 1.0 / 3.0 => 1.0 - 3.0 * q2,
            DensityFn::Nishimura => 1.5 * (1.0 - q).powi(2),
            DensityFn::Murakami => (1.0 - q2).powi(2),
            DensityFn::Wendland => (1.0 - q).powi(4) * (4.0 * q + 1.0),
            // The thesis leaves Blinn's a and b open: not a reference.
            DensityFn::Blinn => f64::NAN,
        }
    };
    // NaN (no formula) or a threshold the centre never reaches: no surface.
    if k * d(0.0) <= t || d(0.0).is_nan() {
        return None;
    }
    // Every function falls monotonically from q = 0 to 0 at q = 1: bisection.
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if k * d(mid) > t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi) * r)
}

const EPS: f64 = 1e-7;

impl Reference {
    /// The nearest sphere hit along o + t d beyond EPS: (t, outward unit normal).
    fn hit(&self, o: DVec3, d: DVec3) -> Option<(f64, DVec3)> {
        let mut best: Option<(f64, DVec3)> = None;
        for s in &self.spheres {
            let oc = o - s.center;
            let b = oc.dot(d);
            let c = oc.length_squared() - s.radius * s.radius;
            let disc = b * b - c;
            if disc < 0.0 {
                continue;
            }
            let q = disc.sqrt();
            for t in [-b - q, -b + q] {
                if t > EPS && best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, (o + t * d - s.center) / s.radius));
                    break;
                }
            }
        }
        best
    }

    /// Radiance along the ray (o, d) carrying weight `w`, at recursion `depth`, with the
    /// ray cone (width at o, spread).
    fn trace(
        &self,
        o: DVec3,
        d: DVec3,
        w: DVec3,
        (depth, inside): (u32, bool),
        cone: (f64, f64),
    ) -> DVec3 {
        let Some((t, n)) = self.hit(o, d) else {
            return w * self.env.color(d, cone);
        };
        let x = o + t * d;
        let at = cone.0 + cone.1 * t;
        let deeper = |dir: DVec3, w2: DVec3, into: bool, from: DVec3| -> DVec3 {
            // Reflected (same side) cones bend twice as much as refracted ones.
            let turns = if into == inside { 2.0 } else { 1.0 };
            let c = (at, cone.1 + turns * at / self.cone_radius);
            match depth + 1 > self.depth {
                true => w2 * self.env.color(dir, c),
                false => self.trace(from, dir, w2, (depth + 1, into), c),
            }
        };
        let nn = if inside { -n } else { n };
        let cos_i = (-d.dot(nn)).clamp(0.0, 1.0);
        let rd = reflect(d, nn);
        let off = nn * 1e-6;
        match self.look {
            Look::Phong { base } => {
                let l = sun();
                let h = (l - d).normalize();
                w * (base * (0.15 + 0.85 * n.dot(l).max(0.0))
                    + DVec3::splat(0.6) * n.dot(h).max(0.0).powi(64))
            }
            Look::Conductor { n: ni, k } => {
                let f = DVec3::new(
                    schlick(conductor_f0(ni.x, k.x), cos_i),
                    schlick(conductor_f0(ni.y, k.y), cos_i),
                    schlick(conductor_f0(ni.z, k.z), cos_i),
                );
                deeper(rd, w * f, inside, x + off)
            }
            Look::Dielectric { ior, sigma } => {
                // Beer-Lambert along the path just travelled inside.
                let w = match inside {
                    true => {
                        w * DVec3::new(
                            (-sigma.x * t).exp(),
                            (-sigma.y * t).exp(),
                            (-sigma.z * t).exp(),
                        )
                    }
                    false => w,
                };
                let (n1, n2) = if inside { (ior, 1.0) } else { (1.0, ior) };
                let f = fresnel_dielectric(cos_i, n1, n2);
                let mut c = deeper(rd, w * f, inside, x + off);
                if let Some(td) = refract(d, nn, n1, n2).filter(|_| f < 1.0) {
                    c += deeper(td.normalize(), w * (1.0 - f), !inside, x - off);
                }
                c
            }
        }
    }

    /// The picture from `cam`, `width` x `height`, RGBA8 as the renderer writes it.
    pub fn render(&self, cam: &Camera, width: u32, height: u32) -> Vec<u8> {
        self.render_with_cones(cam, width, height, true)
    }

    /// `render`, with each pixel's ray cone or with none (`cones` false: the ground's
    /// checks point-sampled, as the renderer drew them before it filtered them).
    pub fn render_with_cones(&self, cam: &Camera, width: u32, height: u32, cones: bool) -> Vec<u8> {
        let eye = cam.eye.as_dvec3();
        let fwd = (cam.target.as_dvec3() - eye).normalize();
        let right = fwd.cross(cam.up.as_dvec3()).normalize();
        let up = right.cross(fwd);
        let tan = (cam.fov_y_deg as f64).to_radians() * 0.5;
        let (ty, tx) = (tan.tan(), tan.tan() * cam.aspect as f64);
        let mut out = Vec::with_capacity((width * height * 4) as usize);
        for y in 0..height {
            for x in 0..width {
                let nx = (x as f64 + 0.5) / width as f64 * 2.0 - 1.0;
                // Vulkan clip space: the first row is the top of the picture.
                let ny = (y as f64 + 0.5) / height as f64 * 2.0 - 1.0;
                let dir = |nx: f64| (fwd + nx * tx * right - ny * ty * up).normalize();
                let d = dir(nx);
                // The pixel's cone: the angle to the next pixel's ray (as the renderer).
                let spread = match cones {
                    true => (dir(nx + 2.0 / width as f64) - d).length(),
                    false => 0.0,
                };
                let c = self.trace(eye, d, DVec3::ONE, (0, false), (0.0, spread));
                for v in [c.x, c.y, c.z] {
                    out.push((v.clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0).round() as u8);
                }
                out.push(255);
            }
        }
        out
    }
}
