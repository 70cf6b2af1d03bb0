//! Particle-system scenes: built-ins (`fountain`, `smoke`, `flock`, `rain`) and TOML files holding
//! `[[system]]` tables (see tests/scenes/). Built-ins use no asset files.
use crate::error::{Error, Result};
use crate::kinds::{Integrator, SortAlgo, SpriteMode};
use crate::psys::spec::*;
use crate::scene::character::CharacterDesc;
use crate::scene::schema::CameraDesc;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const BUILT_IN: &[&str] = &["fountain", "smoke", "flock", "rain"];

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

fn vary3(mean: [f32; 3], variance: [f32; 3]) -> Vec3 {
    Vary { mean, variance }
}
fn vary(mean: f32, variance: f32) -> Scalar {
    Vary { mean, variance }
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
    pub fn built_in(name: &str) -> Option<Self> {
        let camera = |eye, target, fov| CameraDesc { eye, target, fov };
        Some(match name {
            // Water thrown up from a nozzle, falling back onto the ground and bouncing,
            // fading as it dies: sprites sorted back to front (the counting sort).
            "fountain" => {
                let mut water = base_system(
                    "water",
                    1 << 15,
                    emitter(Shape::Disc, [0.0, 0.3, 0.0], 0.04, vary(240.0, 60.0)),
                    ParticleSpec {
                        offset: vary3([0.0; 3], [0.0; 3]),
                        velocity: vary3([0.0, 5.2, 0.0], [0.0, 0.3, 0.0]),
                        spread: 9.0,
                        size: vary(0.05, 0.015),
                        life: vary(2.6, 0.4),
                        color: Vary {
                            mean: [0.45, 0.65, 1.0, 0.55],
                            variance: [0.05, 0.05, 0.0, 0.1],
                        },
                    },
                );
                water.over_life.opacity = vec![[0.0, 1.0], [0.75, 0.9], [1.0, 0.0]];
                water.over_life.color = vec![[0.0, 0.9, 0.95, 1.0], [1.0, 0.55, 0.7, 1.0]];
                water.collider.push(ColliderSpec::ground(0.0, 0.35, 0.25));
                water.damping = 0.05;
                let mut spray = base_system(
                    "spray",
                    1 << 13,
                    emitter(Shape::Disc, [0.0, 0.3, 0.0], 0.03, vary(60.0, 20.0)),
                    ParticleSpec {
                        offset: vary3([0.0; 3], [0.0; 3]),
                        velocity: vary3([0.0, 5.6, 0.0], [0.0, 0.6, 0.0]),
                        spread: 16.0,
                        size: vary(0.0, 0.0),
                        life: vary(2.0, 0.5),
                        color: Vary {
                            mean: [0.8, 0.9, 1.0, 0.8],
                            variance: [0.0; 4],
                        },
                    },
                );
                spray.draw = Some(SpriteMode::Streaks);
                spray.collider.push(ColliderSpec::ground(0.0, 0.2, 0.5));
                spray.over_life.opacity = vec![[0.0, 1.0], [1.0, 0.0]];
                Self {
                    name: name.into(),
                    frames: 180,
                    dt: 1.0 / 60.0,
                    camera: camera([0.0, 1.7, 5.2], [0.0, 1.1, 0.0], 40.0),
                    background: default_sky(),
                    system: vec![water, spray],
                    character: None,
                }
            }
            // Smoke rising from a sphere, pushed by wind and stirred by curl noise,
            // growing and fading: soft noisy sprites, sorted.
            "smoke" => {
                let mut smoke = base_system(
                    "smoke",
                    1 << 12,
                    emitter(Shape::Sphere, [-0.8, 0.2, 0.0], 0.15, vary(12.0, 4.0)),
                    ParticleSpec {
                        offset: vary3([0.0; 3], [0.0; 3]),
                        velocity: vary3([0.0, 0.7, 0.0], [0.15, 0.1, 0.15]),
                        spread: 0.0,
                        size: vary(0.35, 0.1),
                        life: vary(4.0, 1.0),
                        color: Vary {
                            mean: [0.62, 0.62, 0.66, 0.5],
                            variance: [0.04, 0.04, 0.04, 0.1],
                        },
                    },
                );
                smoke.sprite = Some(SpriteTexture::Smoke);
                smoke.gravity = [0.0, 0.25, 0.0]; // buoyancy
                smoke.wind = [0.5, 0.0, 0.0, 0.4];
                smoke.damping = 0.3;
                smoke.force.push(ForceSpec {
                    kind: ForceKind::Curl,
                    at: [0.0; 3],
                    axis: [0.0, 1.0, 0.0],
                    strength: 1.2,
                    eps: 0.01,
                    scale: 1.1,
                    speed: 0.4,
                });
                smoke.over_life.size = vec![[0.0, 0.5], [1.0, 2.6]];
                smoke.over_life.opacity = vec![[0.0, 0.0], [0.12, 1.0], [1.0, 0.0]];
                smoke.over_life.color = vec![[0.0, 1.0, 0.9, 0.8], [1.0, 0.75, 0.75, 0.8]];
                Self {
                    name: name.into(),
                    frames: 240,
                    dt: 1.0 / 60.0,
                    camera: camera([0.0, 1.4, 4.6], [0.0, 1.2, 0.0], 45.0),
                    background: [0.16, 0.2, 0.28],
                    system: vec![smoke],
                    character: None,
                }
            }
            // Boids in a room with a pillar: flocking on the neighbour grid, avoiding the
            // walls and the pillar ahead of them.
            "flock" => {
                let lo = [-3.0, 0.0, -2.0];
                let hi = [3.0, 3.0, 2.0];
                let mut birds = base_system(
                    "boids",
                    4096,
                    emitter(Shape::Sphere, [0.0, 1.5, 0.0], 1.2, vary(0.0, 0.0)),
                    ParticleSpec {
                        offset: vary3([0.0; 3], [0.0; 3]),
                        velocity: vary3([0.0; 3], [1.2, 0.6, 1.2]),
                        spread: 0.0,
                        size: vary(0.06, 0.01),
                        life: vary(1.0e6, 0.0),
                        color: Vary {
                            mean: [0.95, 0.75, 0.35, 1.0],
                            variance: [0.05, 0.15, 0.1, 0.0],
                        },
                    },
                );
                birds.emitter.rate = None;
                birds.emitter.burst = 4096;
                birds.gravity = [0.0; 3];
                let room = ColliderSpec {
                    kind: ColliderKind::Box,
                    min: lo,
                    max: hi,
                    inside: true,
                    restitution: 1.0,
                    ..ColliderSpec::ground(0.0, 1.0, 0.0)
                };
                let pillar = ColliderSpec {
                    kind: ColliderKind::Capsule,
                    a: [0.0, -1.0, 0.0],
                    b: [0.0, 4.0, 0.0],
                    radius: 0.35,
                    restitution: 1.0,
                    ..ColliderSpec::ground(0.0, 1.0, 0.0)
                };
                birds.collider = vec![room, pillar];
                birds.boids = Some(BoidsSpec {
                    radius: 0.5,
                    separation_radius: 0.15,
                    separation: 0.01,
                    alignment: 4.0,
                    cohesion: 1.0,
                    avoidance: 8.0,
                    look_ahead: 0.5,
                    max_speed: 2.0,
                    min_speed: 0.6,
                    max_steer: 6.0,
                    bounds: [lo, hi],
                });
                Self {
                    name: name.into(),
                    frames: 300,
                    dt: 1.0 / 60.0,
                    camera: camera([0.0, 2.6, 6.5], [0.0, 1.3, 0.0], 50.0),
                    background: [0.55, 0.68, 0.85],
                    system: vec![birds],
                    character: None,
                }
            }
            // Rain on a walking character: drops become splashes where they hit the
            // ground or the body's capsules (a type change), and the wet skin drips (a
            // mesh emitter).
            "rain" => rain(),
            _ => return None,
        })
    }

    /// A built-in particle scene, or a TOML file with `[[system]]` tables; None for any
    /// other scene (the caller tries the SPH scenes).
    pub fn find(name_or_path: &str) -> Result<Option<Self>> {
        if let Some(s) = Self::built_in(name_or_path) {
            return Ok(Some(s));
        }
        let path = Path::new(name_or_path);
        if !path.is_file() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            path: name_or_path.into(),
            source: e,
        })?;
        // Only files with [[system]] and no fluid [domain] are particle scenes (SPH scenes
        // may hold systems too). A file too malformed to parse is still one when it
        // declares [[system]] and no [domain], so its error is the particle scene's.
        let declares = |table: &str| text.lines().any(|l| l.trim_start().starts_with(table));
        let is_particles = match text.parse::<toml::Table>() {
            Ok(t) => t.contains_key("system") && !t.contains_key("domain"),
            Err(_) => declares("[[system]]") && !declares("[domain]"),
        };
        if !is_particles {
            return Ok(None);
        }
        let mut s: Self = toml::from_str(&text)
            .map_err(|e| crate::scene::schema::toml_error(name_or_path, &text, &e))?;
        if s.name.is_empty() {
            s.name = path
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
        }
        s.validate()?;
        Ok(Some(s))
    }

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

/// The `rain` scene: the built-in walker on a square path under rain.
fn rain() -> ParticleScene {
    let ground = ColliderSpec::ground(0.0, 0.0, 0.6);
    let body = ColliderSpec {
        kind: ColliderKind::Character,
        ..ColliderSpec::ground(0.0, 0.1, 0.3)
    };
    let mut drops = base_system(
        "rain",
        1 << 15,
        emitter(Shape::Box, [0.0, 4.5, 0.0], 2.5, vary(500.0, 60.0)),
        ParticleSpec {
            offset: vary3([0.0; 3], [0.0; 3]),
            velocity: vary3([0.4, -7.0, 0.0], [0.05, 0.6, 0.05]),
            spread: 0.0,
            size: vary(0.01, 0.0),
            life: vary(3.0, 0.0),
            color: Vary {
                mean: [0.7, 0.8, 1.0, 0.5],
                variance: [0.05, 0.05, 0.0, 0.15],
            },
        },
    );
    drops.emitter.half = [2.5, 0.1, 2.5];
    drops.draw = Some(SpriteMode::Streaks);
    drops.collider = vec![ground.clone(), body.clone()];
    drops.event = vec![EventSpec {
        on: EventKind::Collision,
        spawn: "splash".into(),
        count: vary(1.0, 0.0),
        inherit: 0.15,
        keep_parent: false,
        along_normal: true,
    }];
    let mut splash = base_system(
        "splash",
        1 << 14,
        emitter(Shape::Point, [0.0; 3], 0.0, vary(0.0, 0.0)),
        ParticleSpec {
            offset: vary3([0.0, 0.01, 0.0], [0.0; 3]),
            velocity: vary3([0.0, 1.3, 0.0], [0.0, 0.5, 0.0]),
            spread: 55.0,
            size: vary(0.03, 0.01),
            life: vary(0.35, 0.1),
            color: Vary {
                mean: [0.8, 0.88, 1.0, 0.8],
                variance: [0.0, 0.0, 0.0, 0.1],
            },
        },
    );
    splash.collider = vec![ground.clone(), body.clone()];
    splash.over_life.opacity = vec![[0.0, 1.0], [1.0, 0.0]];
    // The wet skin drips: drops born on the skinned surface fall and die on the ground.
    let mut drips = base_system(
        "drips",
        1 << 12,
        emitter(Shape::Mesh, [0.0; 3], 0.0, vary(6.0, 3.0)),
        ParticleSpec {
            offset: vary3([0.0; 3], [0.0; 3]),
            velocity: vary3([0.0, 0.1, 0.0], [0.02, 0.05, 0.02]),
            spread: 0.0,
            size: vary(0.025, 0.005),
            life: vary(1.5, 0.3),
            color: Vary {
                mean: [0.55, 0.75, 1.0, 0.9],
                variance: [0.0; 4],
            },
        },
    );
    drips.collider = vec![ColliderSpec {
        kill: true,
        ..ground
    }];
    let speed = 0.6;
    ParticleScene {
        name: "rain".into(),
        frames: 180,
        dt: 1.0 / 60.0,
        camera: CameraDesc {
            eye: [0.0, 2.0, 5.5],
            target: [0.0, 0.9, 0.0],
            fov: 45.0,
        },
        background: [0.12, 0.14, 0.18],
        system: vec![drops, splash, drips],
        character: Some(CharacterDesc {
            // The walk cycle's stride (about 0.8 m a cycle) matched to the path speed.
            speed: speed / 0.8,
            path: vec![
                [-1.0, 0.0, 0.8],
                [1.0, 0.0, 0.8],
                [1.0, 0.0, -0.8],
                [-1.0, 0.0, -0.8],
            ],
            path_speed: speed,
            ..CharacterDesc::new("builtin:walker")
        }),
    }
}

/// A scene's systems checked together: unique names, each system's spec, and the
/// systems its events spawn (present, and with state).
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
