//! The built-in scenes: small literals over a few presets (waters, a liquid character's
//! pool, a dam break, a motion trail), each a whole [`Scene`] as a file would give it.
use super::schema::{CameraDesc, Look, Scene, MAIN_TARGET};
use crate::control::timeline::{Action, Event};
use crate::sph::params::{Collider, Eos, FluidParams};
use crate::sph::setup::{Ball, Block, Domain};

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
pub(crate) fn released_water() -> FluidParams {
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
) -> super::schema::TargetDesc {
    super::schema::TargetDesc {
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
}
