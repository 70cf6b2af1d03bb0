//! A scene's `[emission]`: the character sheds particles from its surface (seed 002).
//! The settings (switches override the scene's), the per-frame counters read back after
//! each frame, `emission.csv`, and `stats.emission`: particles alive, births per second,
//! the speed at birth against the surface's, and the uniformity of births over the
//! surface (the coefficient of variation of births per unit area over buckets of
//! triangles of equal area).
use crate::emission::emit::EmitSettings;
use crate::emission::EmitterKind;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

fn yes() -> bool {
    true
}

/// TOML `[emission]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmissionDesc {
    /// Particle slots the emitter recycles (`--particles` sets it).
    pub slots: u32,
    #[serde(default)]
    pub emitter: Option<EmitterKind>,
    /// Seconds (default 2).
    #[serde(default)]
    pub life_limit: Option<f32>,
    /// Births per second at most (default: every due slot, Algorithm 1).
    #[serde(default)]
    pub rate: Option<f32>,
    /// k in units of the surface velocity (default 1).
    #[serde(default)]
    pub transfer: Option<f32>,
    /// UV atlas texels (default 512 x 512).
    #[serde(default)]
    pub uv_size: Option<[u32; 2]>,
    /// The character's capsules are colliders for the fluid (default on).
    #[serde(default = "yes")]
    pub collide: bool,
    /// Colour of emitted particles.
    #[serde(default = "water")]
    pub color: [f32; 3],
    /// The scene's own fluid are emitter slots too, alive at the start with ages spread
    /// over (0, life limit): they die in turn and come back from the character (a steady
    /// turnover from the first step, as benchmarks want).
    #[serde(default)]
    pub recycle: bool,
}

fn water() -> [f32; 3] {
    [0.2, 0.45, 1.0]
}

pub const DEFAULT_UV_SIZE: [u32; 2] = [512, 512];

/// What a run sets over a scene's `[emission]` (`settings::emission_overrides`).
#[derive(Clone, Copy, Debug, Default)]
pub struct EmissionOverrides {
    pub emitter: Option<EmitterKind>,
    pub life_limit: Option<f32>,
    pub rate: Option<f32>,
    pub transfer: Option<f32>,
    pub uv_size: Option<[u32; 2]>,
}

impl EmissionDesc {
    pub fn new(slots: u32) -> Self {
        Self {
            slots,
            emitter: None,
            life_limit: None,
            rate: None,
            transfer: None,
            uv_size: None,
            collide: true,
            color: water(),
            recycle: false,
        }
    }

    /// The effective settings: the overrides (the switches') over the scene's values
    /// over the defaults.
    pub fn resolve(&self, e: &EmissionOverrides) -> Result<(EmitterKind, EmitSettings, [u32; 2])> {
        let d = EmitSettings::default();
        let s = EmitSettings {
            limit: e.life_limit.or(self.life_limit).unwrap_or(d.limit),
            rate: e.rate.or(self.rate),
            transfer: e.transfer.or(self.transfer).unwrap_or(d.transfer),
            dtau: d.dtau,
        };
        s.validate()?;
        let size = e.uv_size.or(self.uv_size).unwrap_or(DEFAULT_UV_SIZE);
        let kind = e.emitter.or(self.emitter).unwrap_or(EmitterKind::Uv);
        Ok((kind, s, size))
    }

    pub fn validate(&self, scene: &str) -> Result<()> {
        if self.slots == 0 && !self.recycle {
            return Err(Error::Param(format!(
                "scene {scene}: [emission] needs at least one slot (or recycle = true)"
            )));
        }
        self.resolve(&EmissionOverrides::default())
            .map(|_| ())
            .map_err(|e| Error::Param(format!("scene {scene}: [emission] {e}")))
    }
}
