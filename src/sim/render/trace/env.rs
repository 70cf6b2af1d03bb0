//! What a ray that leaves the fluid sees: the renderer's procedural environment as its
//! specification gives it (README, "Metaball renderer"): a sky graded from a pale horizon
//! to blue at the zenith with a sun (a sharp disc and a soft halo), and below the horizon
//! a ground of 0.5 m checks on the plane one metre under the ray's origin, darkening
//! towards the horizon and box-filtered over the ray's cone; or an equirectangular image
//! (`--sky`), read bilinearly (wrapping in longitude, clamped in latitude, interpolated in
//! its stored sRGB then made linear with gamma 2.2, as the renderer documents). Linear
//! colour, f64.
use glam::DVec3;

/// The sun's direction.
pub fn sun() -> DVec3 {
    DVec3::new(0.4, 0.8, 0.3).normalize()
}

fn mix(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    a * (1.0 - t) + b * t
}

/// Where rays that leave end.
#[derive(Clone, Debug)]
pub enum Env {
    Procedural,
    /// An equirectangular image: width, height, RGB8 rows from the top (+Y).
    Image(u32, u32, Vec<[u8; 3]>),
}

impl Env {
    /// The colour seen along `d` by a ray cone `(width, spread)` (`filtered_check`).
    pub fn color(&self, d: DVec3, cone: (f64, f64)) -> DVec3 {
        match self {
            Env::Procedural => environment(d, cone),
            Env::Image(w, h, px) => image(*w as i64, *h as i64, px, d),
        }
    }
}

fn image(w: i64, h: i64, px: &[[u8; 3]], d: DVec3) -> DVec3 {
    use std::f64::consts::PI;
    let u = d.z.atan2(d.x) / (2.0 * PI) + 0.5;
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    let (sx, sy) = (u * w as f64 - 0.5, v * h as f64 - 0.5);
    let (fx, fy) = (sx.floor(), sy.floor());
    let (ax, ay) = (sx - fx, sy - fy);
    let x0 = (fx as i64).rem_euclid(w);
    let x1 = (x0 + 1) % w;
    let (y0, y1) = ((fy as i64).clamp(0, h - 1), (fy as i64 + 1).clamp(0, h - 1));
    let at = |x: i64, y: i64| {
        let p = px[(y * w + x) as usize];
        DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) / 255.0
    };
    let top = mix(at(x0, y0), at(x1, y0), ax);
    let bottom = mix(at(x0, y1), at(x1, y1), ax);
    let c = mix(top, bottom, ay);
    DVec3::new(c.x.powf(2.2), c.y.powf(2.2), c.z.powf(2.2))
}

/// The checks' parity at (x, y) (one check per unit) box-filtered over a square of side
/// `w`: the integral of the checker over it, in closed form (Quilez): the floor / 2
/// parity as w -> 0, 0.5 when w covers many checks.
pub fn filtered_check(x: f64, y: f64, w: f64) -> f64 {
    let w = w.max(1e-4);
    let tri = |v: f64| ((v * 0.5).rem_euclid(1.0) - 0.5).abs();
    let i = |v: f64| 2.0 * (tri(v - 0.5 * w) - tri(v + 0.5 * w)) / w;
    0.5 - 0.5 * i(x) * i(y)
}

/// The procedural environment's colour in direction `d` (unit) for a ray cone `(width,
/// spread)`: the ground's checks filtered over the cone's footprint on the plane one
/// metre down (the spread times d(tan)/d(angle) = 1 + tan^2, plus the width over the
/// ray's slope), as the renderer's `sky_color`.
pub fn environment(d: DVec3, (width, spread): (f64, f64)) -> DVec3 {
    if d.y < 0.0 {
        let down = (-d.y).max(1e-3);
        let (gx, gz) = (d.x / down, d.z / down);
        let foot = spread * (1.0 + gx * gx + gz * gz) + width / down;
        let check = filtered_check(gx * 2.0, gz * 2.0, foot * 2.0);
        let dark = DVec3::new(0.25, 0.23, 0.2);
        let light = DVec3::new(0.45, 0.42, 0.38);
        return mix(dark, light, check) * (0.6 + 0.4 * (-d.y * 4.0).min(1.0));
    }
    let horizon = DVec3::new(0.75, 0.82, 0.9);
    let zenith = DVec3::new(0.25, 0.45, 0.8);
    let c = mix(horizon, zenith, d.y.powf(0.6));
    let s = d.dot(sun()).max(0.0);
    c + DVec3::new(1.0, 0.9, 0.7) * (s.powi(400) * 8.0 + s.powi(8) * 0.2)
}
