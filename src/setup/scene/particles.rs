//! Particle-system scenes: TOML holding `[[system]]` tables and no `[domain]`, built in
//! (scenes/fountain.toml, smoke, flock, rain: no asset files) or a user's (tests/scenes/).
use crate::error::{Error, Result};
use crate::kinds::SortAlgo;
use crate::psys::spec::*;
use crate::psys::{Integrator, SpriteMode};
use crate::scene::character::CharacterDesc;
use crate::scene::schema::CameraDesc;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParticleScene {
    #[serde(default)]
    pub name: String,
    /// Frames `run` plays by default.
    #[serde(default = "default_frames")]
    pub frames: u64,
    /// Seconds per frame (one step per frame).
    #[serde(default = "default_dt")]
    pub dt: f32,
    pub camera: CameraDesc,
    /// Background colour (linear RGB).
    #[serde(default = "default_sky")]
    pub background: [f32; 3],
    pub system: Vec<SystemSpec>,
    /// An animated character the systems emit from (`mesh`) or collide with
    /// (`character`), drawn with them, depth-tested.
    #[serde(default)]
    pub character: Option<CharacterDesc>,
}

fn default_frames() -> u64 {
    180
}
fn default_dt() -> f32 {
    1.0 / 60.0
}
fn default_sky() -> [f32; 3] {
    [0.02, 0.02, 0.04]
}

/// A system with no forces, colliders or curves: the built-ins start from it.
pub fn base_system(
    name: &str,
    capacity: u32,
    emitter: EmitterSpec,
    particle: ParticleSpec,
) -> SystemSpec {
    SystemSpec {
        name: name.into(),
        capacity,
        integrator: None,
        draw: None,
        sort: None,
        sprite: None,
        point_px: 3.0,
        emitter,
        particle,
        over_life: OverLife::default(),
        gravity: [0.0, -9.81, 0.0],
        wind: [0.0; 4],
        damping: 0.0,
        force: vec![],
        collider: vec![],
        death: DeathSpec::default(),
        event: vec![],
        boids: None,
    }
}

pub fn emitter(shape: Shape, centre: [f32; 3], radius: f32, rate: Scalar) -> EmitterSpec {
    EmitterSpec {
        shape,
        centre,
        half: [radius; 3],
        radius,
        normal: [0.0, 1.0, 0.0],
        surface: false,
        rate: Some(rate),
        per_area: None,
        orbit: None,
        burst: 0,
    }
}

impl ParticleScene {
    pub fn validate(&self) -> Result<()> {
        match (&self.character, self.system.iter().find(|s| s.uses_character())) {
            (None, Some(s)) => {
                return Err(Error::Param(format!(
                    "scene {}: system '{}' emits from or collides with the character, but the scene has no [character]",
                    self.name, s.name
                )))
            }
            (Some(c), _) => c.validate(&self.name)?,
            _ => {}
        }
        if self.system.is_empty() {
            return Err(Error::Param(format!("scene {}: no [[system]]", self.name)));
        }
        if !(self.dt > 0.0 && self.dt <= 0.1) {
            return Err(Error::Param(format!(
                "scene {}: dt must be in (0, 0.1] s",
                self.name
            )));
        }
        validate_systems(&self.name, &self.system)
    }

    /// The switches applied: --integrator and --draw to every system
    /// (`set_integrator_draw`), --sort to every sorted (non-point) one, --particles as
    /// every system's capacity with its birth rate scaled to match.
    pub fn with_switches(
        mut self,
        integrator: Option<Integrator>,
        draw: Option<SpriteMode>,
        sort: Option<SortAlgo>,
        particles: Option<u32>,
    ) -> Result<Self> {
        set_integrator_draw(&mut self.system, integrator, draw);
        for s in &mut self.system {
            if let Some(n) = particles {
                let k = n as f32 / s.capacity as f32;
                if let Some(r) = &mut s.emitter.rate {
                    r.mean *= k;
                    r.variance *= k;
                }
                if let Some(a) = &mut s.emitter.per_area {
                    *a *= k;
                }
                s.emitter.burst = (s.emitter.burst as f32 * k).round() as u32;
                s.capacity = n;
            }
        }
        if let Some(algo) = sort {
            let mut any = false;
            for s in self
                .system
                .iter_mut()
                .filter(|s| s.draw() != SpriteMode::Points)
            {
                s.sort = Some(algo);
                any = true;
            }
            if !any {
                return Err(Error::Param(format!(
                    "--sort does not apply to scene {}: its systems draw opaque points",
                    self.name
                )));
            }
        }
        self.validate()?;
        Ok(self)
    }
}

pub fn validate_systems(scene: &str, systems: &[SystemSpec]) -> Result<()> {
    for (i, s) in systems.iter().enumerate() {
        if systems[..i].iter().any(|o| o.name == s.name) {
            return Err(Error::Param(format!(
                "scene {scene}: two systems named '{}'",
                s.name
            )));
        }
        s.validate()?;
        for ev in &s.event {
            let Some(t) = systems.iter().find(|t| t.name == ev.spawn) else {
                return Err(Error::Param(format!(
                    "scene {scene}: system '{}' spawns '{}', which is not a [[system]] of it",
                    s.name, ev.spawn
                )));
            };
            if t.integrator() == Integrator::Closed {
                return Err(Error::Unsupported(format!(
                    "scene {scene}: '{}' is spawned by events, so it needs state: --integrator euler or verlet, not closed",
                    t.name
                )));
            }
        }
    }
    Ok(())
}

/// --integrator and --draw applied to every system.
pub fn set_integrator_draw(
    systems: &mut [SystemSpec],
    integrator: Option<Integrator>,
    draw: Option<SpriteMode>,
) {
    for s in systems {
        if let Some(i) = integrator {
            s.integrator = Some(i);
        }
        if let Some(d) = draw {
            s.draw = Some(d);
        }
    }
}
