//! GPU particle systems (seed 003): integrators against the closed form, energy, emission
//! statistics, depth sorts, collisions, and the alive/dead lists.
#[path = "../common/mod.rs"]
mod common;
use common::{finish, fluidform, text};
use fluidform::gpu::{Context, Labels};
use fluidform::kinds::SortAlgo;
use fluidform::psys::cpu::{attractor_potential, closed_pos, partitions};
use fluidform::psys::spec::*;
use fluidform::psys::{FrameInfo, ParticleSystem, Passes};
use fluidform::psys::{Integrator, SpriteMode};
use fluidform::render::Camera;
use fluidform::scene::particles::{base_system, emitter, ParticleScene};
use glam::Vec3;

mod composite;
mod mesh;
mod motion;
mod sorting;
mod types;

fn cam() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 1.5, 6.0),
        Vec3::new(0.0, 1.0, 0.0),
        45.0,
        1.0,
    )
}

fn frame(cam: &Camera, k: u64, dt: f32) -> FrameInfo<'_> {
    fluidform::psys::frame::frame_info(cam, dt, k, 256, 256)
}

/// A spec with colourful, distinct particles (their colour identifies them across systems
/// made with the same seed) and long lives.
fn ballistic(integrator: Integrator, capacity: u32) -> SystemSpec {
    let mut s = base_system(
        "ballistic",
        capacity,
        emitter(
            Shape::Sphere,
            [0.0, 1.0, 0.0],
            0.3,
            Vary {
                mean: 0.0,
                variance: 0.0,
            },
        ),
        ParticleSpec {
            offset: Vary {
                mean: [0.0; 3],
                variance: [0.0; 3],
            },
            velocity: Vary {
                mean: [0.5, 4.0, -0.3],
                variance: [1.0, 1.0, 1.0],
            },
            spread: 0.0,
            size: Vary {
                mean: 0.05,
                variance: 0.0,
            },
            life: Vary {
                mean: 100.0,
                variance: 0.0,
            },
            color: Vary {
                mean: [0.5; 4],
                variance: [0.5; 4],
            },
        },
    );
    s.integrator = Some(integrator);
    s
}

/// Record `steps` steps (births only in the first) in one command buffer.
#[allow(clippy::too_many_arguments)]
fn steps(
    ctx: &Context,
    passes: &Passes,
    s: &mut ParticleSystem,
    cam: &Camera,
    dt: f32,
    from: u64,
    steps: u64,
    first_births: u32,
) {
    ctx.one_shot(|cmd| {
        for k in from..from + steps {
            let births = if k == 0 { first_births } else { 0 };
            s.record_births(ctx, cmd, &mut Labels, passes, &frame(cam, k, dt), births);
        }
    })
    .unwrap();
}

fn key(c: [f32; 4]) -> [u32; 4] {
    c.map(f32::to_bits)
}

/// Boids' steering on the CPU, brute force over the alive slots (boids.comp's rules);
/// `body`: the character's posed capsules (end, end, radius).
fn cpu_steer(
    spec: &SystemSpec,
    d: &fluidform::psys::system::StateDump,
    slot: u32,
    body: &[(Vec3, Vec3, f32)],
) -> (Vec3, u32) {
    let b = spec.boids.as_ref().unwrap();
    let p = Vec3::from_slice(&d.pos[slot as usize][..3]);
    let v = Vec3::from_slice(&d.vel[slot as usize][..3]);
    let (mut sep, mut mv, mut mp, mut n) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0u32);
    for &o in &d.alive {
        let q = Vec3::from_slice(&d.pos[o as usize][..3]);
        let dd = p - q;
        let d2 = dd.length_squared();
        if o == slot || d2 > b.radius * b.radius {
            continue;
        }
        n += 1;
        mv += Vec3::from_slice(&d.vel[o as usize][..3]);
        mp += q;
        if d2 < b.separation_radius * b.separation_radius {
            sep += dd / d2.max(1e-8);
        }
    }
    let mut a = b.separation * sep;
    if n > 0 {
        a += b.alignment * (mv / n as f32 - v) + b.cohesion * (mp / n as f32 - p);
    }
    // Avoidance of the room (a container), a pillar or the body's capsules ahead.
    let ahead = p + v * b.look_ahead;
    let capsule = |a0: Vec3, a1: Vec3, r: f32| {
        let h = ((ahead - a0).dot(a1 - a0) / (a1 - a0).length_squared().max(1e-12)).clamp(0.0, 1.0);
        let d = ahead - (a0 + h * (a1 - a0));
        (d.length() < r).then(|| d.normalize())
    };
    for c in &spec.collider {
        let ns: Vec<Option<Vec3>> = match c.kind {
            ColliderKind::Box => {
                let q = ahead.clamp(Vec3::from(c.min), Vec3::from(c.max));
                vec![(q != ahead).then(|| (q - ahead).normalize())]
            }
            ColliderKind::Capsule => vec![capsule(Vec3::from(c.a), Vec3::from(c.b), c.radius)],
            ColliderKind::Character => body.iter().map(|&(a0, a1, r)| capsule(a0, a1, r)).collect(),
            _ => unreachable!("the flocks have rooms, pillars and bodies"),
        };
        for n in ns.into_iter().flatten() {
            a += b.avoidance * n;
        }
    }
    if a.length() > b.max_steer {
        a *= b.max_steer / a.length();
    }
    (a, n)
}
