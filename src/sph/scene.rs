//! SPH scenes: a domain box, fluid parameters, fluid blocks and spheres (filled on a
//! lattice at the rest spacing), colliders and a camera. Built in or read from TOML.
use super::params::{Collider, Eos, FluidParams, MAX_COLLIDERS};
use crate::control::timeline::{Action, Event};
use crate::error::{Error, Result};
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

pub(crate) fn white() -> [f32; 3] {
    [0.25, 0.55, 1.0]
}

/// An axis-aligned box of fluid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Block {
    pub min: [f32; 3],
    pub max: [f32; 3],
    #[serde(default)]
    pub group: u32,
    #[serde(default = "white")]
    pub color: [f32; 3],
    #[serde(default)]
    pub velocity: [f32; 3],
}

/// A ball of fluid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ball {
    pub center: [f32; 3],
    pub radius: f32,
    #[serde(default)]
    pub group: u32,
    #[serde(default = "white")]
    pub color: [f32; 3],
    #[serde(default)]
    pub velocity: [f32; 3],
}

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
    pub targets: Vec<crate::control::target::TargetDesc>,
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

/// A scene's defaults for its picture; `--material`, `--width` and `--height` override them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Look {
    pub material: Option<crate::config::Material>,
    /// [width, height] in pixels.
    pub size: Option<[u32; 2]>,
    /// Draw the domain as a glass tank (default on).
    pub tank: Option<bool>,
    /// Metaballs (default) or points (coloured by particle, as groups need).
    pub render: Option<crate::config::RenderKind>,
}

impl Look {
    /// `sw` with this look's values where the switches leave them unset.
    pub fn apply(&self, sw: &crate::config::Switches) -> crate::config::Switches {
        let mut sw = sw.clone();
        if sw.metaball.material.is_none() {
            sw.metaball.material = self.material;
        }
        if let Some([w, h]) = self.size {
            sw.frame.width = sw.frame.width.or(Some(w));
            sw.frame.height = sw.frame.height.or(Some(h));
        }
        sw
    }
}

/// A fill region: box bounds, inside test, group, colour, velocity.
type Region = (
    [f32; 3],
    [f32; 3],
    Box<dyn Fn([f32; 3]) -> bool>,
    u32,
    [f32; 3],
    [f32; 3],
);

/// Initial particles: positions (xyz, w = 0), velocities, colours (rgb, w = group bits).
pub struct Particles {
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    pub attr: Vec<[f32; 4]>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
}

pub const BUILT_IN: &[&str] = &[
    "demo",
    "dam-break",
    "drop",
    "resting-block",
    "walker",
    "character",
    "giraffe",
    "union",
    "morph",
    "two-groups",
    "trail",
    "game",
];

/// Kelager's water with a Tait equation of state stiff enough for < 1% compression in
/// a metre of water (c = 40 m/s), dt = 4e-4 s (CFL 0.35), 10 steps per frame.
fn stiff_water() -> FluidParams {
    FluidParams {
        eos: Eos::Tait,
        sound_speed: 40.0,
        clamp_negative_pressure: true,
        dt: 4e-4,
        substeps: 10,
        restitution: 0.1,
        friction: 0.05,
        ..FluidParams::default()
    }
}

/// Water for pools under control targets: Tait with c = 20 m/s, 12 steps of 0.9 ms a
/// frame, walls with a little friction: a pool drained into its character leaves a film
/// whose particles jam along the frictionless floor's edges and corners and race along
/// them (10-16 m/s seen), then up the vertical edges as spray (CesiumMan: 10% of the
/// mass); 2% of the tangential speed per contact step stops that.
fn pool_water() -> FluidParams {
    FluidParams {
        eos: Eos::Tait,
        sound_speed: 20.0,
        clamp_negative_pressure: true,
        dt: 9e-4,
        substeps: 12,
        friction: 0.02,
        ..FluidParams::default()
    }
}

/// Pool water for scenes that release their targets: a metre's collapse hits the pool at
/// about 4.4 m/s, and weakly compressible SPH wants c >= 10 v (c = 20 m/s exploded in
/// the collapse); c = 40 m/s at half the step, 24 steps of 0.45 ms a frame.
fn released_water() -> FluidParams {
    FluidParams {
        sound_speed: 40.0,
        dt: 4.5e-4,
        substeps: 24,
        ..pool_water()
    }
}

/// A pool `depth` deep on the floor of the box [lo, hi] under a built-in shape standing at
/// the origin, pulled in by control particles with adaptive pressure; seen from the front
/// (camera x and distance `view`), 240 x 240.
fn liquid(
    name: &str,
    (lo, hi): ([f32; 3], [f32; 3]),
    depth: f32,
    shape: &str,
    speed: f32,
    view: [f32; 2],
) -> Scene {
    Scene {
        name: name.into(),
        domain: Domain { min: lo, max: hi },
        fluid: pool_water(),
        blocks: vec![Block {
            min: lo,
            max: [hi[0], depth, hi[2]],
            group: 0,
            color: [0.2, 0.45, 1.0],
            velocity: [0.0; 3],
        }],
        balls: vec![],
        colliders: vec![],
        camera: Some(CameraDesc {
            eye: [view[0], 0.75, view[1]],
            target: [view[0], 0.5, 0.0],
            fov: 40.0,
        }),
        frames: 150,
        look: Look {
            material: Some(crate::config::Material::Tinted),
            size: Some([240, 240]),
            tank: Some(false),
            ..Look::default()
        },
        character: Some(crate::scene::character::CharacterDesc {
            speed,
            ..crate::scene::character::CharacterDesc::new(shape)
        }),
        control: Some(crate::control::target::ControlDesc {
            adaptive: crate::config::Adaptive::On,
            ..crate::control::target::ControlDesc::default()
        }),
        targets: vec![],
        timeline: vec![],
        emission: None,
        system: vec![],
        pool: None,
    }
}

/// `liquid`: the walker at half speed over a 0.9 x 0.6 m pool 0.1 m deep.
fn walker_pool(name: &str) -> Scene {
    liquid(
        name,
        ([-0.45, 0.0, -0.3], [0.45, 1.2, 0.3]),
        0.1,
        "builtin:walker",
        0.5,
        [0.0, 2.3],
    )
}

/// `liquid` in a 1.2 m wide box (room for a second target), the walker at `x`, 320 x 240.
fn wide(name: &str, x: f32) -> Scene {
    let mut s = liquid(
        name,
        ([-0.6, 0.0, -0.3], [0.6, 1.2, 0.3]),
        0.1,
        "builtin:walker",
        0.5,
        [0.0, 2.8],
    );
    if let Some(c) = &mut s.character {
        c.position = [x, 0.0, 0.0];
    }
    s.look.size = Some([320, 240]);
    s
}

/// The built-in capsule, `height` tall, standing at `at`.
fn capsule(height: f32, at: [f32; 3]) -> crate::scene::character::CharacterDesc {
    crate::scene::character::CharacterDesc {
        height: Some(height),
        position: at,
        ..crate::scene::character::CharacterDesc::new("builtin:capsule")
    }
}

/// A control target with the liquid scenes' settings (adaptive pressure), controlling
/// `group` (None: all).
fn target(
    name: &str,
    character: crate::scene::character::CharacterDesc,
    group: Option<u32>,
) -> crate::control::target::TargetDesc {
    crate::control::target::TargetDesc {
        name: name.into(),
        character,
        control: crate::control::target::ControlDesc {
            adaptive: crate::config::Adaptive::On,
            group,
            ..crate::control::target::ControlDesc::default()
        },
    }
}

/// Seed 002's setting: the walker runs a rectangular loop of `loop_` (half sizes x, z) at
/// `speed` m/s through the box [lo, hi], shedding `slots` particles from its UV atlas at
/// `rate` per second, living `life` seconds; its capsules are colliders. Seen from the
/// front and above (camera at height and distance `view`).
#[allow(clippy::too_many_arguments)]
fn trail(
    name: &str,
    (lo, hi): ([f32; 3], [f32; 3]),
    loop_: [f32; 2],
    speed: f32,
    slots: u32,
    rate: f32,
    life: f32,
    view: [f32; 2],
) -> Scene {
    let [x, z] = loop_;
    Scene {
        name: name.into(),
        domain: Domain { min: lo, max: hi },
        fluid: pool_water(),
        blocks: vec![],
        balls: vec![],
        colliders: vec![],
        camera: Some(CameraDesc {
            eye: [0.0, view[0], view[1]],
            target: [0.0, 0.3, 0.0],
            fov: 45.0,
        }),
        frames: 150,
        look: Look {
            material: Some(crate::config::Material::Tinted),
            size: Some([320, 240]),
            tank: Some(false),
            ..Look::default()
        },
        character: Some(crate::scene::character::CharacterDesc {
            // The walk cycle's stride (about 0.8 m a cycle) matched to the path speed.
            speed: speed / 0.8,
            path: vec![[-x, 0.0, z], [x, 0.0, z], [x, 0.0, -z], [-x, 0.0, -z]],
            path_speed: speed,
            ..crate::scene::character::CharacterDesc::new("builtin:walker")
        }),
        control: None,
        targets: vec![],
        timeline: vec![],
        emission: Some(crate::scene::emission::EmissionDesc {
            rate: Some(rate),
            life_limit: Some(life),
            ..crate::scene::emission::EmissionDesc::new(slots)
        }),
        system: vec![],
        pool: None,
    }
}

/// A water column of size `column` at the origin released in a tank of size `tank`, seen
/// from the front at height and distance `view`, 600 frames of stiff water.
fn dam_break(name: &str, tank: [f32; 3], column: [f32; 3], view: [f32; 2]) -> Scene {
    Scene {
        name: name.into(),
        domain: Domain {
            min: [0.0; 3],
            max: tank,
        },
        fluid: stiff_water(),
        blocks: vec![Block {
            min: [0.0; 3],
            max: column,
            group: 0,
            color: [0.2, 0.45, 1.0],
            velocity: [0.0; 3],
        }],
        balls: vec![],
        colliders: vec![],
        camera: Some(CameraDesc {
            eye: [0.5 * tank[0], view[0], view[1]],
            target: [0.5 * tank[0], 0.25 * tank[1], 0.5 * tank[2]],
            fov: 45.0,
        }),
        frames: 600,
        look: Look::default(),
        character: None,
        control: None,
        targets: vec![],
        timeline: vec![],
        emission: None,
        system: vec![],
        pool: None,
    }
}

/// A scene file's parse error as one line: where, then what (the parser's own text draws
/// the line).
pub fn toml_error(file: &str, text: &str, e: &toml::de::Error) -> Error {
    let at = e.span().map(|r| {
        let before = &text[..r.start.min(text.len())];
        let line = before.matches('\n').count() + 1;
        let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        format!(" line {line} column {col}:")
    });
    Error::Param(format!(
        "scene file {file}:{} {}",
        at.unwrap_or_default(),
        e.message().trim().replace('\n', " ")
    ))
}

impl Scene {
    pub fn built_in(name: &str) -> Option<Self> {
        let blue = [0.2, 0.45, 1.0];
        let orange = [1.0, 0.55, 0.15];
        Some(match name {
            // The default: a small dam break made to watch in a minute or two on a 2-core
            // CPU (7.5K particles, 96 frames of 10.8 ms, tinted water at 300 x 200).
            "demo" => Scene {
                fluid: FluidParams {
                    sound_speed: 20.0,
                    dt: 9e-4,
                    substeps: 12,
                    ..stiff_water()
                },
                frames: 96,
                look: Look {
                    material: Some(crate::config::Material::Tinted),
                    size: Some([300, 200]),
                    tank: None,
                    render: None,
                },
                ..dam_break(name, [1.5, 0.9, 0.5], [0.5, 0.63, 0.5], [0.95, 2.3])
            },
            // 32K particles: a 0.8 x 1.0 x 0.8 m column released in a 2.4 m long tank.
            "dam-break" => dam_break(name, [2.4, 1.4, 0.8], [0.8, 1.0, 0.8], [1.6, 3.4]),
            // A ball (group 1) falling into a shallow pool (group 0).
            "drop" => Scene {
                name: name.into(),
                domain: Domain {
                    min: [0.0, 0.0, 0.0],
                    max: [1.0, 1.0, 1.0],
                },
                fluid: stiff_water(),
                blocks: vec![Block {
                    min: [0.0, 0.0, 0.0],
                    max: [1.0, 0.15, 1.0],
                    group: 0,
                    color: blue,
                    velocity: [0.0; 3],
                }],
                balls: vec![Ball {
                    center: [0.5, 0.6, 0.5],
                    radius: 0.12,
                    group: 1,
                    color: orange,
                    velocity: [0.0, -1.0, 0.0],
                }],
                colliders: vec![],
                camera: Some(CameraDesc {
                    eye: [0.5, 1.1, 2.3],
                    target: [0.5, 0.3, 0.5],
                    fov: 45.0,
                }),
                frames: 240,
                look: Look::default(),
                character: None,
                control: None,
                targets: vec![],
                timeline: vec![],
                emission: None,
                system: vec![],
                pool: None,
            },
            // Kelager's water exactly (ideal gas, k = 3 J, dt = 0.01 s), resting on the floor.
            "resting-block" => Scene {
                name: name.into(),
                domain: Domain {
                    min: [0.0, 0.0, 0.0],
                    max: [0.6, 0.6, 0.6],
                },
                fluid: FluidParams::default(),
                blocks: vec![Block {
                    min: [0.1, 0.0, 0.1],
                    max: [0.5, 0.25, 0.5],
                    group: 0,
                    color: blue,
                    velocity: [0.0; 3],
                }],
                balls: vec![],
                colliders: vec![],
                camera: Some(CameraDesc {
                    eye: [0.3, 0.6, 1.4],
                    target: [0.3, 0.1, 0.3],
                    fov: 45.0,
                }),
                frames: 240,
                look: Look::default(),
                character: None,
                control: None,
                targets: vec![],
                timeline: vec![],
                emission: None,
                system: vec![],
                pool: None,
            },
            // A liquid character: its pool rises into the built-in walker (control particles,
            // adaptive pressure, the fidelity preset) and follows its walk at half speed.
            // (Released, the collapse's pool went unstable near 2 s with WCSPH: not shown.)
            "character" => Scene {
                frames: 200,
                fluid: released_water(),
                // The water it is made of, under its feet (scene::fit); the spacing comes
                // from its thinnest part.
                blocks: vec![],
                pool: Some(crate::scene::fit::PoolDesc::default()),
                timeline: vec![Event::new(0.0, Action::Attach, Some(MAIN_TARGET))],
                look: Look {
                    material: Some(crate::config::Material::Tinted),
                    size: Some([240, 240]),
                    tank: Some(false),
                    render: None,
                },
                ..walker_pool(name)
            },
            // The built-in long-necked shape (neck 2.5 rest spacings thick) filled from a
            // pool: the adaptive-pressure test (compare --adaptive off|on|smooth).
            "giraffe" => Scene {
                frames: 600,
                ..liquid(
                    name,
                    ([-0.4, 0.0, -0.25], [0.6, 1.2, 0.25]),
                    0.08,
                    "builtin:giraffe",
                    1.0,
                    [0.1, 2.4],
                )
            },
            // A capsule of water that morphs into the walker at 1 s.
            "morph" => Scene {
                frames: 220,
                targets: vec![target("capsule", capsule(0.6, [0.0, 0.0, 0.0]), None)],
                timeline: vec![
                    Event::new(0.0, Action::Attach, Some("capsule")),
                    Event::new(1.0, Action::Switch, Some(MAIN_TARGET)),
                ],
                ..walker_pool(name)
            },
            // The walker fills; at 0.8 s a capsule beside it is added to the target.
            "union" => {
                let mut s = wide(name, -0.2);
                s.frames = 200;
                s.targets = vec![target("capsule", capsule(0.6, [0.3, 0.0, 0.0]), None)];
                s.timeline = vec![
                    Event::new(0.0, Action::Attach, Some(MAIN_TARGET)),
                    Event::new(0.8, Action::Union, Some("capsule")),
                ];
                s
            }
            // A pool of blue (group 0) and orange (group 1) stripes: the walker pulls the
            // blue out, a capsule beside it the orange (each target reaches the fluid
            // within h_c of its control particles); released at 1.5 s, they mix.
            // The walker runs a 1.2 x 0.6 m loop shedding water: 8192 slots, 3000 births
            // a second living up to 2 s (seed 002's UV emitter).
            "trail" => trail(
                name,
                ([-1.0, 0.0, -0.7], [1.0, 1.3, 0.7]),
                [0.6, 0.3],
                0.8,
                8192,
                3000.0,
                2.0,
                [1.6, 2.6],
            ),
            // Seed 002's game scene: 65537 particles shed by a character running a 2.4 x
            // 1.6 m loop through a 4 x 3 m room around two pillars.
            "game" => {
                let mut s = trail(
                    name,
                    ([-2.0, 0.0, -1.5], [2.0, 2.0, 1.5]),
                    [1.2, 0.8],
                    1.2,
                    65537,
                    22000.0,
                    4.0,
                    [2.6, 4.6],
                );
                s.colliders = [-0.5f32, 0.5]
                    .iter()
                    .map(|&x| Collider::Capsule {
                        a: [x, 0.0, 0.0],
                        b: [x, 1.2, 0.0],
                        radius: 0.12,
                        velocity: [0.0; 3],
                    })
                    .collect();
                s.frames = 300;
                s
            }
            "two-groups" => {
                let mut s = wide(name, -0.2);
                // Stripes 0.1 m wide along x.
                s.blocks = (0..12)
                    .map(|k| Block {
                        min: [-0.6 + 0.1 * k as f32, 0.0, -0.3],
                        max: [-0.5 + 0.1 * k as f32, 0.1, 0.3],
                        group: k % 2,
                        color: [blue, [1.0, 0.55, 0.15]][k as usize % 2],
                        velocity: [0.0; 3],
                    })
                    .collect();
                // Points show the groups' colours (metaballs have one material).
                s.look.render = Some(crate::config::RenderKind::Points);
                if let Some(c) = &mut s.control {
                    c.group = Some(0);
                }
                s.frames = 220;
                s.fluid = released_water();
                s.targets = vec![target("capsule", capsule(0.6, [0.3, 0.0, 0.0]), Some(1))];
                s.timeline = vec![
                    Event::new(0.0, Action::Attach, Some(MAIN_TARGET)),
                    Event::new(0.0, Action::Union, Some("capsule")),
                    Event::new(1.5, Action::Release, None),
                ];
                s
            }
            // The built-in character alone, walking in place: two cycles at 30 fps.
            "walker" => Scene {
                name: name.into(),
                domain: Domain {
                    min: [-1.0, 0.0, -1.0],
                    max: [1.0, 1.5, 1.0],
                },
                fluid: FluidParams::default(),
                blocks: vec![],
                balls: vec![],
                colliders: vec![],
                camera: Some(CameraDesc {
                    eye: [1.4, 0.95, 2.2],
                    target: [0.0, 0.5, 0.0],
                    fov: 40.0,
                }),
                frames: 60,
                look: Look {
                    size: Some([320, 320]),
                    ..Look::default()
                },
                character: Some(crate::scene::character::CharacterDesc::new(
                    "builtin:walker",
                )),
                control: None,
                targets: vec![],
                timeline: vec![],
                emission: None,
                system: vec![],
                pool: None,
            },
            _ => return None,
        })
    }

    /// A built-in name or a path to a TOML scene file.
    pub fn load(name_or_path: &str) -> Result<Self> {
        if let Some(s) = Self::built_in(name_or_path) {
            return Ok(s);
        }
        let path = Path::new(name_or_path);
        if !path.exists() {
            return Err(Error::Param(format!(
                "unknown scene '{name_or_path}': not a built-in ({}, orbits, {}) nor an existing file",
                BUILT_IN.join(", "),
                crate::psys::scenes::BUILT_IN.join(", ")
            )));
        }
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            path: name_or_path.into(),
            source: e,
        })?;
        let mut s: Scene =
            toml::from_str(&text).map_err(|e| toml_error(name_or_path, &text, &e))?;
        // A liquid character's file that leaves [fluid] out gets the built-in liquid
        // characters' water (Kelager's defaults take 10 ms ideal-gas steps).
        let has_fluid = toml::from_str::<toml::Table>(&text).is_ok_and(|t| t.contains_key("fluid"));
        if !has_fluid && (s.control.is_some() || !s.targets.is_empty()) {
            s.fluid = released_water();
        }
        // A character file is named relative to the scene file.
        let dir = path.parent().unwrap_or(Path::new("."));
        let chars = s.character.iter_mut();
        for c in chars.chain(s.targets.iter_mut().map(|t| &mut t.character)) {
            let f = Path::new(&c.file);
            if !c.file.starts_with("builtin:") && f.is_relative() {
                c.file = dir.join(f).display().to_string();
            }
        }
        s.validate()?;
        Ok(s)
    }

    pub fn validate(&self) -> Result<()> {
        self.fluid.validate()?;
        let (lo, hi) = (self.domain.min, self.domain.max);
        if (0..3)
            .any(|k| hi[k].is_nan() || hi[k] <= lo[k] || !lo[k].is_finite() || !hi[k].is_finite())
        {
            return Err(Error::Param(format!(
                "scene {}: empty domain {lo:?}..{hi:?}",
                self.name
            )));
        }
        if self.colliders.len() > MAX_COLLIDERS {
            return Err(Error::Param(format!(
                "scene {}: {} colliders, at most {MAX_COLLIDERS}",
                self.name,
                self.colliders.len()
            )));
        }
        for c in &self.colliders {
            c.to_gpu()?;
        }
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
        crate::psys::scenes::validate_systems(&self.name, &self.system)
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

    pub fn particles(&self, seed: u64) -> Particles {
        let s = self.fluid.spacing();
        let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
        let mut out = Particles {
            pos: Vec::new(),
            vel: Vec::new(),
            attr: Vec::new(),
        };
        let mut regions: Vec<Region> = Vec::new();
        for b in &self.blocks {
            regions.push((
                b.min,
                b.max,
                Box::new(|_| true),
                b.group,
                b.color,
                b.velocity,
            ));
        }
        for b in &self.balls {
            let (c, r) = (b.center, b.radius);
            let inside =
                move |p: [f32; 3]| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f32>() <= r * r;
            regions.push((
                [c[0] - r, c[1] - r, c[2] - r],
                [c[0] + r, c[1] + r, c[2] + r],
                Box::new(inside),
                b.group,
                b.color,
                b.velocity,
            ));
        }
        let (dlo, dhi) = (self.domain.min, self.domain.max);
        for (lo, hi, inside, group, color, vel) in regions {
            let count = |k: usize| (((hi[k] - lo[k]) / s).floor() as i64).max(0);
            for iz in 0..count(2) {
                for iy in 0..count(1) {
                    for ix in 0..count(0) {
                        let mut p = [
                            lo[0] + (ix as f32 + 0.5) * s,
                            lo[1] + (iy as f32 + 0.5) * s,
                            lo[2] + (iz as f32 + 0.5) * s,
                        ];
                        if !inside(p) {
                            continue;
                        }
                        for v in &mut p {
                            *v += rng.random_range(-0.01..0.01) * s;
                        }
                        if (0..3).any(|k| p[k] < dlo[k] || p[k] > dhi[k]) {
                            continue;
                        }
                        if self.colliders.iter().any(|c| c.distance(p) < 0.0) {
                            continue;
                        }
                        out.pos.push([p[0], p[1], p[2], 0.0]);
                        out.vel.push([vel[0], vel[1], vel[2], 0.0]);
                        out.attr
                            .push([color[0], color[1], color[2], f32::from_bits(group)]);
                    }
                }
            }
        }
        // Emission slots start dead (pos.w < 0) at the domain's centre.
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
