//! Finite-support metaball density functions D(r), r <= R (0 beyond), normalised to
//! D(0) = 1, with their radial derivative for analytic normals. The surface is where the
//! sum over metaballs equals the threshold T.
use crate::render::DensityFn;

/// Blinn's Gaussian b exp(-a r^2) truncated at R, shifted and rescaled so that it reaches
/// 0 continuously at R (a = BLINN_A / R^2).
pub const BLINN_A: f32 = 4.0;

/// The density functions' mathematics.
impl DensityFn {
    /// D(r) for support radius `radius`.
    pub fn value(self, r: f32, radius: f32) -> f32 {
        if r >= radius {
            return 0.0;
        }
        let q = r / radius;
        let q2 = q * q;
        match self {
            DensityFn::Blinn => {
                let floor = (-BLINN_A).exp();
                ((-BLINN_A * q2).exp() - floor) / (1.0 - floor)
            }
            DensityFn::Wyvill => {
                1.0 - 4.0 / 9.0 * q2 * q2 * q2 + 17.0 / 9.0 * q2 * q2 - 22.0 / 9.0 * q2
            }
            DensityFn::Nishimura => {
                if q <= 1.0 / 3.0 {
                    1.0 - 3.0 * q2
                } else {
                    1.5 * (1.0 - q) * (1.0 - q)
                }
            }
            DensityFn::Murakami => (1.0 - q2) * (1.0 - q2),
            DensityFn::Wendland => (1.0 - q).powi(4) * (4.0 * q + 1.0),
        }
    }

    /// dD/dr.
    pub fn derivative(self, r: f32, radius: f32) -> f32 {
        if r >= radius {
            return 0.0;
        }
        let q = r / radius;
        let q2 = q * q;
        let dq = 1.0 / radius;
        let d_dq = match self {
            DensityFn::Blinn => {
                let floor = (-BLINN_A).exp();
                -2.0 * BLINN_A * q * (-BLINN_A * q2).exp() / (1.0 - floor)
            }
            DensityFn::Wyvill => -24.0 / 9.0 * q2 * q2 * q + 68.0 / 9.0 * q2 * q - 44.0 / 9.0 * q,
            DensityFn::Nishimura => {
                if q <= 1.0 / 3.0 {
                    -6.0 * q
                } else {
                    -3.0 * (1.0 - q)
                }
            }
            DensityFn::Murakami => -4.0 * q * (1.0 - q2),
            DensityFn::Wendland => -20.0 * q * (1.0 - q).powi(3),
        };
        d_dq * dq
    }

    /// max |dD/dq| over q = r / R in [0, 1] with a 0.1% margin (sampled at 1e-5 in q; each
    /// slope here is smooth, so the samples miss its peak by far less): one metaball's
    /// field is slope_max / R Lipschitz in x (`--march lipschitz`).
    pub fn slope_max(self) -> f32 {
        let steps = 100_000;
        let peak = (0..=steps)
            .map(|i| self.derivative(i as f32 / steps as f32, 1.0).abs())
            .fold(0.0f32, f32::max);
        peak * 1.001
    }
}
