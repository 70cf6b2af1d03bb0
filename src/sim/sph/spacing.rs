//! `--fluid spacing=S`: the resolution switch (the field `FluidParams::spacing`).
use super::params::FluidParams;
use crate::error::{Error, Result};

impl FluidParams {
    /// Apply `spacing` (see the field): mass, h, dt and steps per frame follow it. Once
    /// applied the implied spacing is S, so applying again changes nothing.
    pub fn resolve_spacing(&mut self) -> Result<()> {
        let Some(s) = self.spacing else {
            return Ok(());
        };
        if !(s.is_finite() && s > 0.0) {
            return Err(Error::Param(format!(
                "--fluid spacing must be positive, got {s}"
            )));
        }
        let r = s / self.spacing();
        if (r - 1.0).abs() < 1e-5 {
            return Ok(());
        }
        let frame = self.dt * self.substeps as f32;
        self.mass = self.rest_density * s * s * s;
        self.h *= r;
        self.dt *= r;
        // Whole steps per frame, the step no longer than the scaled one.
        self.substeps = (frame / self.dt).ceil().max(1.0) as u32;
        self.dt = frame / self.substeps as f32;
        if let Some(m) = &mut self.dt_max {
            *m *= r;
        }
        self.validate()
    }
}
