//! The control switches of a target, resolved (see `target::ControlDesc` for the scene
//! file's and the presets' defaults), with their checks and shader defines.
use crate::control::{Adaptive, ControlMotion};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The control switches and their defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControlSettings {
    /// c_cp (eq. 7; 0: off).
    pub pressure: f32,
    /// h_c (metres).
    pub radius: f32,
    pub adaptive: Adaptive,
    /// Thresholds (fractions of rho_0) and factors of adaptive control pressure.
    pub low: f32,
    pub high: f32,
    pub up: f32,
    pub down: f32,
    /// K of the velocity term (0: off, the thesis).
    pub velocity: f32,
    /// Deficit attraction (m/s^2, 0: off), its reach (metres), damping relative to the
    /// character (1/s, 0: off), and where control velocities come from.
    pub attraction: f32,
    pub reach: f32,
    pub damping: f32,
    pub motion: ControlMotion,
    /// The controlled group, or ALL_GROUPS.
    pub group: u32,
    /// Steps between refreshes of the control's sums (1: every step, the thesis; see
    /// `control::cache`).
    pub every: u32,
}

impl ControlSettings {
    pub fn validate(&self) -> Result<()> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(Error::Param(format!(
                "--control-radius must be positive, got {}",
                self.radius
            )));
        }
        // c_cp = 0 turns eq. 7 off (the force pass then skips its walk over h_c).
        let non_negative = [
            ("--control-pressure", self.pressure),
            ("--control-velocity", self.velocity),
            ("--control-attraction", self.attraction),
            ("--control-damping", self.damping),
        ];
        for (k, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Param(format!("{k} must be at least 0, got {v}")));
            }
        }
        if !(self.reach.is_finite() && self.reach > 0.0 && self.reach <= 16.0 * self.radius) {
            return Err(Error::Param(format!(
                "--control-reach must be positive and at most 16 control radii ({} m), got {}",
                16.0 * self.radius,
                self.reach
            )));
        }
        if !(1..=super::cache::MAX_EVERY).contains(&self.every) {
            return Err(Error::Param(format!(
                "--control-every must be in 1..={}, got {}",
                super::cache::MAX_EVERY,
                self.every
            )));
        }
        if !(0.0 < self.low && self.low < self.high && self.up > 0.0 && self.down > 0.0) {
            return Err(Error::Param(format!(
                "adaptive pressure needs 0 < low < high and positive factors, got low {} high {} up {} down {}",
                self.low, self.high, self.up, self.down
            )));
        }
        Ok(())
    }

    pub fn adaptive_id(a: Adaptive) -> u32 {
        match a {
            Adaptive::Off => 0,
            Adaptive::On => 1,
            Adaptive::Smooth => 2,
        }
    }

    /// The shader defines of adaptive mode `a`.
    pub fn defines(a: Adaptive) -> Vec<(&'static str, String)> {
        vec![
            ("ADAPTIVE_OFF", "0".into()),
            ("ADAPTIVE_ON", "1".into()),
            ("ADAPTIVE_SMOOTH", "2".into()),
            ("ADAPTIVE", Self::adaptive_id(a).to_string()),
        ]
    }
}
