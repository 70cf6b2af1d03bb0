//! The scene schema: a domain box, fluid parameters, fluid blocks and balls, colliders,
//! a camera, and the features that drive the fluid (characters, control targets, a
//! timeline, emission, particle systems). Read from TOML (`load.rs`): a user's file or a
//! built-in's (`builtin.rs`).
use crate::error::{Error, Result};
use crate::sph::params::{Collider, FluidParams};
pub use crate::sph::setup::{fill, white, Ball, Block, Domain, Particles, SphSetup};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    #[serde(default = "default_fov")]
    pub fov: f32,
}

fn default_fov() -> f32 {
    45.0
}

/// The control target of `[character]` and `[control]` on the timeline.
pub const MAIN_TARGET: &str = "character";

fn default_frames() -> u64 {
    240
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    pub name: String,
    /// Fitted around the character's motion when a scene with `[character]` gives none.
    #[serde(default, skip_serializing_if = "Domain::is_unset")]
    pub domain: Domain,
    #[serde(default)]
    pub fluid: FluidParams,
    #[serde(default)]
    pub blocks: Vec<Block>,
    #[serde(default)]
    pub balls: Vec<Ball>,
    #[serde(default)]
    pub colliders: Vec<Collider>,
    pub camera: Option<CameraDesc>,
    #[serde(default = "default_frames")]
    pub frames: u64,
    /// How the scene is shown unless switches say otherwise.
    #[serde(default)]
    pub look: Look,
    /// An animated character (a scene may have it alone, with no fluid).
    #[serde(default)]
    pub character: Option<crate::scene::character::CharacterDesc>,
    /// Control particles pulling the fluid into the character (needs `character`): the
    /// control target named "character".
    #[serde(default)]
    pub control: Option<crate::control::target::ControlDesc>,
    /// More control targets, by name.
    #[serde(default)]
    pub targets: Vec<TargetDesc>,
    /// When targets attach, switch, unite, release and change strength (default: every
    /// target attached from the start).
    #[serde(default)]
    pub timeline: Vec<crate::control::timeline::Event>,
    /// The character sheds particles (seed 002): slots recycled by Emit.
    #[serde(default)]
    pub emission: Option<crate::scene::emission::EmissionDesc>,
    /// Particle systems (seed 003) played with the fluid and drawn with it, composited
    /// by depth; stepped once per frame of `frame_time`.
    #[serde(default)]
    pub system: Vec<crate::psys::spec::SystemSpec>,
    /// The water a liquid character is made of, sized from `character` (see
    /// `scene::fit`): added to `blocks` when the run starts.
    #[serde(default)]
    pub pool: Option<crate::scene::fit::PoolDesc>,
}

/// A named control target beside the scene's `[character]` (TOML `[[targets]]`): a
/// character or closed mesh, where it stands and how it plays, and its control settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetDesc {
    pub name: String,
    pub character: super::character::CharacterDesc,
    #[serde(default)]
    pub control: crate::control::target::ControlDesc,
}

/// A scene's defaults for its picture; `--material`, `--width` and `--height` override them.
/// A scene with a `[character]` and fluid looks like water unless it says otherwise
/// (`Look::water`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Look {
    pub material: Option<crate::render::Material>,
    /// [width, height] in pixels.
    pub size: Option<[u32; 2]>,
    /// Draw the domain as a glass tank (default on; off in a scene with a `[character]` and fluid).
    pub tank: Option<bool>,
    /// Metaballs (default) or points (coloured by particle, as groups need).
    pub render: Option<crate::render::RenderKind>,
    /// The fluid's surface under metaballs rendering (`--surface`).
    pub surface: Option<crate::render::SurfaceKind>,
}

impl Look {
    /// The defaults of a scene with a character and fluid: water (tinted, under the
    /// sky) and no tank, for each key its `[look]` leaves out.
    pub fn water(&mut self) {
        self.material.get_or_insert(crate::render::Material::Tinted);
        self.tank.get_or_insert(false);
    }
}

impl Scene {
    pub fn validate(&self) -> Result<()> {
        if self.domain.is_unset() {
            return Err(Error::Param(format!(
                "scene {}: no [domain] (only a scene with a [character] has one fitted)",
                self.name
            )));
        }
        SphSetup::from(self).validate()?;
        self.validate_fluid_bodies()?;
        if let Some(c) = &self.character {
            c.validate(&self.name)?;
        }
        if let Some(e) = &self.emission {
            e.validate(&self.name)?;
            if self.character.is_none() {
                return Err(Error::Param(format!(
                    "scene {}: [emission] needs a [character] to shed from",
                    self.name
                )));
            }
        }
        if self.control.is_some() && (self.character.is_none() || !self.has_fluid()) {
            return Err(Error::Param(format!(
                "scene {}: [control] needs a [character] and fluid",
                self.name
            )));
        }
        if !self.targets.is_empty() && !self.has_fluid() {
            return Err(Error::Param(format!(
                "scene {}: [[targets]] need fluid",
                self.name
            )));
        }
        let names = self.control_targets();
        for (i, t) in self.targets.iter().enumerate() {
            t.character.validate(&self.name)?;
            if names[..names.len() - self.targets.len() + i].contains(&t.name) {
                return Err(Error::Param(format!(
                    "scene {}: two control targets named '{}'",
                    self.name, t.name
                )));
            }
        }
        crate::control::timeline::Timeline::new(&self.name, &self.timeline, &names)?;
        if !self.has_fluid() && self.character.is_none() {
            return Err(Error::Param(format!(
                "scene {}: no fluid (blocks or balls) and no character",
                self.name
            )));
        }
        self.validate_systems()
    }

    /// Blocks and balls that are not empty and lie inside the domain (fluid outside it
    /// would be dropped silently).
    fn validate_fluid_bodies(&self) -> Result<()> {
        for b in &self.blocks {
            if (0..3).any(|k| b.max[k].is_nan() || b.max[k] <= b.min[k]) {
                return Err(Error::Param(format!(
                    "scene {}: empty block {:?}..{:?}",
                    self.name, b.min, b.max
                )));
            }
        }
        for b in &self.balls {
            if b.radius.is_nan() || b.radius <= 0.0 {
                return Err(Error::Param(format!(
                    "scene {}: ball radius must be positive",
                    self.name
                )));
            }
        }
        // Fluid outside the domain would be dropped silently: refuse it instead.
        let (dlo, dhi) = (self.domain.min, self.domain.max);
        let outside = |lo: [f32; 3], hi: [f32; 3]| {
            let tol = 1e-4 * (0..3).map(|k| dhi[k] - dlo[k]).fold(0.0f32, f32::max);
            (0..3).any(|k| lo[k] < dlo[k] - tol || hi[k] > dhi[k] + tol)
        };
        for b in &self.blocks {
            if outside(b.min, b.max) {
                return Err(Error::Param(format!(
                    "scene {}: block {:?}..{:?} reaches outside the domain {dlo:?}..{dhi:?}",
                    self.name, b.min, b.max
                )));
            }
        }
        for b in &self.balls {
            let (c, r) = (b.center, b.radius);
            if outside(
                [c[0] - r, c[1] - r, c[2] - r],
                [c[0] + r, c[1] + r, c[2] + r],
            ) {
                return Err(Error::Param(format!(
                    "scene {}: ball at {c:?} of radius {r} reaches outside the domain \
                     {dlo:?}..{dhi:?}",
                    self.name
                )));
            }
        }
        Ok(())
    }

    /// Particle systems play with the fluid, apart from the character.
    fn validate_systems(&self) -> Result<()> {
        if self.system.is_empty() {
            return Ok(());
        }
        if !self.has_fluid() {
            return Err(Error::Param(format!(
                "scene {}: [[system]] without fluid: a character with particle systems is a particle scene (no [domain])",
                self.name
            )));
        }
        if let Some(s) = self.system.iter().find(|s| s.uses_character()) {
            return Err(Error::Unsupported(format!(
                "scene {}: system '{}' emits from or collides with the character, which SPH scenes' systems do not reach yet (a particle scene's [character] does)",
                self.name, s.name
            )));
        }
        crate::scene::particles::validate_systems(&self.name, &self.system)
    }

    /// The names of the control targets: "character" for `[character]` with `[control]`,
    /// then `[[targets]]` in order.
    pub fn control_targets(&self) -> Vec<String> {
        let main = self.control.is_some().then(|| MAIN_TARGET.to_string());
        main.into_iter()
            .chain(self.targets.iter().map(|t| t.name.clone()))
            .collect()
    }

    /// Blocks or balls of fluid, or emission (a scene may hold a character alone).
    pub fn has_fluid(&self) -> bool {
        !(self.blocks.is_empty() && self.balls.is_empty())
            || self.emission.is_some()
            || self.pool.is_some()
    }

    /// The scene scaled about the origin by `s` (geometry and camera; the fluid's
    /// parameters, and so its spacing, stay).
    pub fn scaled(&self, s: f32) -> Self {
        let m = |v: [f32; 3]| [v[0] * s, v[1] * s, v[2] * s];
        let mut out = self.clone();
        out.domain = Domain {
            min: m(self.domain.min),
            max: m(self.domain.max),
        };
        for b in &mut out.blocks {
            b.min = m(b.min);
            b.max = m(b.max);
        }
        for b in &mut out.balls {
            b.center = m(b.center);
            b.radius *= s;
        }
        out.colliders = self.colliders.iter().map(|c| c.scaled(s)).collect();
        if let Some(c) = &mut out.camera {
            c.eye = m(c.eye);
            c.target = m(c.target);
        }
        // The characters grow with the scene (their placement about the origin too).
        let chars = out.character.iter_mut();
        for c in chars.chain(out.targets.iter_mut().map(|t| &mut t.character)) {
            c.position = m(c.position);
            c.path = c.path.iter().map(|p| m(*p)).collect();
            c.path_speed *= s;
            match (c.height, c.scale) {
                (Some(h), _) => c.height = Some(h * s),
                (_, Some(k)) => c.scale = Some(k * s),
                _ => c.scale = Some(s),
            }
        }
        out
    }

    /// Scaled so it holds about `n` particles; with emission, `n` slots in all (the
    /// emitter's are what is left after the scene's own fluid).
    pub fn with_particles(&self, n: u32) -> Self {
        if let Some(e) = &self.emission {
            let mut out = self.clone();
            let own = self.particles(0).len() as u32 - e.slots;
            out.emission.as_mut().expect("emission").slots = n.saturating_sub(own).max(1);
            return out;
        }
        let natural = self.particles(0).len().max(1) as f64;
        self.scaled((n as f64 / natural).cbrt() as f32)
    }

    /// Fill blocks and balls on a cubic lattice at the rest spacing, jittered by 1% of it
    /// (seeded), keeping points inside the domain and outside colliders.
    /// An upper bound of the particles `particles` makes (lattice points in the blocks'
    /// and balls' boxes), computed without making them.
    pub fn estimated_particles(&self) -> f64 {
        let s = self.fluid.spacing() as f64;
        let count = |lo: [f32; 3], hi: [f32; 3]| {
            (0..3)
                .map(|k| ((hi[k] - lo[k]) as f64 / s).floor().max(0.0))
                .product::<f64>()
        };
        let blocks: f64 = self.blocks.iter().map(|b| count(b.min, b.max)).sum();
        let balls: f64 = self
            .balls
            .iter()
            .map(|b| {
                let (c, r) = (b.center, b.radius);
                count(
                    [c[0] - r, c[1] - r, c[2] - r],
                    [c[0] + r, c[1] + r, c[2] + r],
                )
            })
            .sum();
        blocks + balls + self.emission.as_ref().map_or(0.0, |e| e.slots as f64)
    }

    /// Refuse a scene whose particles would not fit, before any is made: more than
    /// `limit`, or more than `bytes_per_particle` each in `memory` bytes.
    pub fn check_size(&self, limit: u64, bytes_per_particle: u64, memory: u64) -> Result<()> {
        let n = self.estimated_particles();
        let why = format!(
            "scene {} implies about {n:.3e} particles at a spacing of {:.3e} m (mass {} kg)",
            self.name,
            self.fluid.spacing(),
            self.fluid.mass
        );
        // The spacing that brings the count down to `fit` particles.
        let works = |fit: f64| self.fluid.spacing() as f64 * (n / fit).cbrt() * 1.01;
        if !n.is_finite() || n > limit as f64 {
            return Err(Error::Param(format!(
                "{why}: at most {limit}; use --fluid spacing={:.3e} or more, or shrink the fluid",
                works(limit as f64)
            )));
        }
        let need = n * bytes_per_particle as f64;
        if memory > 0 && need > memory as f64 {
            return Err(Error::Memory(format!(
                "{why}, about {:.1} GiB, more than the device's {:.1} GiB: use --fluid spacing={:.3e} or more",
                need / (1u64 << 30) as f64,
                memory as f64 / (1u64 << 30) as f64,
                works(memory as f64 / bytes_per_particle as f64)
            )));
        }
        Ok(())
    }

    /// The scene's fluid filled on a lattice (see [`crate::sph::setup::fill`]), then its
    /// emission slots, dead (pos.w < 0) at the domain's centre.
    pub fn particles(&self, seed: u64) -> Particles {
        let mut out = fill(
            self.fluid.spacing(),
            &self.domain,
            (&self.blocks, &self.balls),
            &self.colliders,
            seed,
        );
        let (dlo, dhi) = (self.domain.min, self.domain.max);
        if let Some(e) = &self.emission {
            let c: [f32; 3] = std::array::from_fn(|k| 0.5 * (dlo[k] + dhi[k]));
            let col = e.color;
            for _ in 0..e.slots {
                out.pos.push([c[0], c[1], c[2], -1.0]);
                out.vel.push([0.0; 4]);
                out.attr.push([col[0], col[1], col[2], f32::from_bits(0)]);
            }
        }
        out
    }
}

impl<'a> From<&'a Scene> for SphSetup<'a> {
    fn from(s: &'a Scene) -> Self {
        SphSetup {
            name: &s.name,
            domain: &s.domain,
            fluid: &s.fluid,
            colliders: &s.colliders,
        }
    }
}
