//! Reflection, refraction and absorption, from textbook formulas (f64):
//! - Snell's law in vector form and the exact unpolarised Fresnel reflectance of a
//!   dielectric interface: Hecht, *Optics* (5th ed.), 4.6; Pharr, Jakob & Humphreys,
//!   *Physically Based Rendering* (4th ed.), 9.3.
//! - Conductors: Schlick's approximation F0 + (1 - F0)(1 - cos)^5 (Schlick 1994), with F0
//!   from the complex index n + ik at normal incidence ((n-1)^2 + k^2) / ((n+1)^2 + k^2),
//!   the formula the thesis names (PAPERS.md, section 4).
//! - Beer-Lambert: transmittance exp(-sigma d) along a path of length d.
use glam::DVec3;

/// Mirror `d` about the normal `n` (unit vectors).
pub fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

/// The refracted direction of unit `d` at a surface with unit normal `n` facing the
/// incoming ray, from index `n1` into `n2`; None past the critical angle (total internal
/// reflection).
pub fn refract(d: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let eta = n1 / n2;
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(eta * d + (eta * cos_i - cos_t) * n)
}

/// Exact unpolarised Fresnel reflectance of a dielectric interface for incidence cosine
/// `cos_i`, from `n1` into `n2`: the mean of the s and p reflectances; 1 past the
/// critical angle.
pub fn fresnel_dielectric(cos_i: f64, n1: f64, n2: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The critical angle (radians) from `n1` into a rarer `n2`.
pub fn critical_angle(n1: f64, n2: f64) -> f64 {
    (n2 / n1).asin()
}

/// Normal-incidence reflectance of a conductor of complex index n + ik.
pub fn conductor_f0(n: f64, k: f64) -> f64 {
    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
}

/// Schlick's approximation for a conductor of normal reflectance `f0`.
pub fn schlick(f0: f64, cos_i: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - cos_i.clamp(0.0, 1.0)).powi(5)
}

/// Beer-Lambert transmittance through `d` metres of a medium absorbing `sigma` per metre.
pub fn transmittance(sigma: f64, d: f64) -> f64 {
    (-sigma * d).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflected_and_transmitted_energy_is_one() {
        // A dielectric neither makes nor loses energy: R + T = 1 at every angle, from
        // either side, with T = 1 - R and R in [0, 1].
        for (n1, n2) in [(1.0, 1.33), (1.33, 1.0), (1.0, 1.5), (1.5, 1.0)] {
            for i in 0..=90 {
                let c = (i as f64).to_radians().cos();
                let r = fresnel_dielectric(c, n1, n2);
                assert!((0.0..=1.0).contains(&r), "R {r} at {i} deg, {n1}->{n2}");
            }
        }
        // Normal incidence: ((n1 - n2) / (n1 + n2))^2 (Hecht 4.67).
        let r0 = fresnel_dielectric(1.0, 1.0, 1.33);
        assert!((r0 - (0.33f64 / 2.33).powi(2)).abs() < 1e-12);
        // Brewster's angle: the p reflectance vanishes, R = Rs / 2.
        let b = (1.5f64).atan();
        let cos_t = (1.0 - (b.sin() / 1.5).powi(2)).sqrt();
        let rs = ((b.cos() - 1.5 * cos_t) / (b.cos() + 1.5 * cos_t)).powi(2);
        assert!((fresnel_dielectric(b.cos(), 1.0, 1.5) - 0.5 * rs).abs() < 1e-12);
    }

    #[test]
    fn total_internal_reflection_starts_at_the_critical_angle() {
        let (n1, n2) = (1.33, 1.0);
        let c = critical_angle(n1, n2);
        let n = DVec3::Z;
        let dir = |a: f64| DVec3::new(a.sin(), 0.0, -a.cos());
        assert!(refract(dir(c - 1e-6), n, n1, n2).is_some());
        assert!(refract(dir(c + 1e-6), n, n1, n2).is_none());
        assert!(fresnel_dielectric((c - 1e-3).cos(), n1, n2) < 1.0);
        assert_eq!(fresnel_dielectric((c + 1e-3).cos(), n1, n2), 1.0);
        // Just below it the refracted ray grazes the surface.
        let t = refract(dir(c - 1e-9), n, n1, n2).unwrap();
        assert!(t.z.abs() < 1e-3 && (t.length() - 1.0).abs() < 1e-9);
        // Snell: n1 sin(i) = n2 sin(t).
        let t = refract(dir(0.3), n, n1, n2).unwrap();
        assert!((n1 * 0.3f64.sin() - n2 * t.x).abs() < 1e-12);
    }

    #[test]
    fn absorption_grows_with_thickness() {
        let mut last = 1.0;
        for k in 1..10 {
            let t = transmittance(6.0, 0.01 * k as f64);
            assert!(t < last);
            last = t;
        }
        // Two layers absorb as one of their summed thickness.
        let (a, b) = (transmittance(2.0, 0.1), transmittance(2.0, 0.3));
        assert!((a * b - transmittance(2.0, 0.4)).abs() < 1e-15);
        assert!((conductor_f0(1.5, 0.0) - 0.04).abs() < 1e-12);
        assert_eq!(schlick(0.5, 1.0), 0.5);
        assert_eq!(schlick(0.5, 0.0), 1.0);
    }
}
