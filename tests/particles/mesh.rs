//! Emitters on a skinned mesh.

use super::*;

#[test]
fn mesh_emitter_births_lie_on_the_skin_and_the_body_collides() {
    use fluidform::character::capsules;
    use fluidform::character::Skinning;
    use fluidform::psys::character::CharacterLink;
    use fluidform::render::ShowMesh;
    use fluidform::run::targets::character::SceneCharacter;
    use fluidform::scene::character::CharacterDesc;
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let desc = CharacterDesc::new("builtin:walker");
    let ch = SceneCharacter::new(&ctx, &desc, Skinning::Lbs, ShowMesh::Shaded).unwrap();
    let link = CharacterLink::new(&ctx, &ch.ch).unwrap();
    let mats = ch.matrices(0.0);
    ctx.one_shot(|cmd| {
        ch.record(&ctx, cmd, &mut Labels, 0.0).unwrap();
        link.record(&ctx, cmd, &mats);
    })
    .unwrap();
    let (skin, rain, flock) = specs();
    let mut systems = vec![
        ParticleSystem::new(&ctx, &passes, &skin, 0, 1).unwrap(),
        ParticleSystem::new(&ctx, &passes, &rain, 1, 2).unwrap(),
        ParticleSystem::new(&ctx, &passes, &flock, 2, 3).unwrap(),
    ];
    let dt = 1.0 / 60.0;
    let step = |systems: &mut Vec<ParticleSystem>, frames: std::ops::Range<u64>| {
        ctx.one_shot(|cmd| {
            for k in frames {
                let f = FrameInfo {
                    character: Some(link.bufs(ch.surface())),
                    ..frame(&cam, k, dt)
                };
                fluidform::psys::frame::record_simulation(
                    &ctx,
                    cmd,
                    &mut Labels,
                    &passes,
                    systems,
                    &f,
                )
                .unwrap();
            }
        })
        .unwrap();
    };
    // (The flock is checked while still around the body.)
    step(&mut systems, 0..1);
    let flock_state = systems[2].read(&ctx).unwrap();
    step(&mut systems, 1..2);
    let steer = systems[2].read_steer(&ctx).unwrap();
    step(&mut systems, 2..60);
    let (p, _) = ch.ch.skinned_at(&mats, Skinning::Lbs).unwrap();
    births_on_the_skin(&systems[0].read(&ctx).unwrap(), &p, &ch.ch.mesh.indices);
    let posed: Vec<_> = capsules::of(&ch.ch)
        .iter()
        .map(|c| c.posed(&mats))
        .collect();
    rain_rests_on_the_body(&systems[1].read(&ctx).unwrap(), &posed);
    // The flock's GPU steering against the CPU's, the body's capsules included.
    let body: Vec<_> = posed.iter().map(|c| (c.a, c.b, c.r)).collect();
    let (mut worst, mut avoiding, mut count_mismatch) = (0.0f32, 0, 0);
    for &i in &flock_state.alive {
        let (a, n) = cpu_steer(&flock, &flock_state, i, &body);
        let (alone, _) = cpu_steer(&flock, &flock_state, i, &[]);
        avoiding += ((a - alone).length() > 1e-3) as u32;
        let g = steer[i as usize];
        count_mismatch += (g[3] as u32 != n) as u32;
        worst = worst.max((Vec3::from_slice(&g[..3]) - a).length() / (1.0 + a.length()));
    }
    assert_eq!(flock_state.alive.len(), 1024);
    eprintln!("{avoiding} of 1024 boids look ahead into the body");
    assert!(
        avoiding > 20,
        "only {avoiding} boids look ahead into the body"
    );
    assert!(
        count_mismatch <= 2,
        "{count_mismatch} boids saw other flockmates"
    );
    assert!(worst < 2e-3, "steering differs from the CPU's by {worst}");
    for s in &mut systems {
        s.destroy(&ctx);
    }
    let (mut ch, mut link, mut passes) = (ch, link, passes);
    link.destroy(&ctx);
    ch.destroy(&ctx);
    passes.destroy(&ctx);
    finish(&ctx);
}

/// Skin births, rain onto the body, and a flock around it.
fn specs() -> (SystemSpec, SystemSpec, SystemSpec) {
    // Births on the skin: a mesh emitter at rest, no gravity.
    let mut skin = ballistic(Integrator::Euler, 600);
    skin.emitter.shape = Shape::Mesh;
    skin.particle.velocity = Vary {
        mean: [0.0; 3],
        variance: [0.0; 3],
    };
    skin.gravity = [0.0; 3];
    skin.emitter.burst = 600;
    // Rain from above onto the body alone: it must rest on it, never inside a capsule.
    let mut rain = ballistic(Integrator::Euler, 4000);
    rain.name = "rain".into();
    rain.emitter = emitter(
        Shape::Box,
        [0.0, 2.2, 0.0],
        0.35,
        Vary {
            mean: 60.0,
            variance: 0.0,
        },
    );
    rain.particle.velocity = Vary {
        mean: [0.0, -3.0, 0.0],
        variance: [0.0; 3],
    };
    rain.collider = vec![ColliderSpec {
        kind: ColliderKind::Character,
        ..ColliderSpec::ground(0.0, 0.0, 1.0)
    }];
    // Boids around the body steer away from its capsules ahead of them.
    let mut flock = ballistic(Integrator::Euler, 1024);
    flock.name = "flock".into();
    flock.gravity = [0.0; 3];
    flock.emitter.burst = 1024;
    flock.emitter.rate = None;
    flock.emitter.centre = [0.0, 1.0, 0.0];
    flock.emitter.radius = 0.3;
    flock.particle.velocity = Vary {
        mean: [0.0; 3],
        variance: [1.0; 3],
    };
    let mut boids = ParticleScene::built_in("flock").unwrap().system[0]
        .boids
        .clone()
        .unwrap();
    boids.bounds = [[-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]];
    boids.radius = 0.15;
    boids.separation_radius = 0.05;
    boids.look_ahead = 0.1;
    flock.boids = Some(boids);
    flock.collider = rain.collider.clone();
    (skin, rain, flock)
}

/// Every skin birth lies on the posed skin `p` (triangles `indices`), over most of its height.
fn births_on_the_skin(d: &fluidform::psys::system::StateDump, p: &[Vec3], indices: &[u32]) {
    let tris: Vec<[Vec3; 3]> = indices
        .chunks_exact(3)
        .map(|t| [p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]])
        .collect();
    let (lo_y, hi_y) = p
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v.y), h.max(v.y)));
    assert_eq!(d.alive.len(), 600, "the skin emitter's births");
    let (mut ymin, mut ymax) = (f32::MAX, f32::MIN);
    for &i in &d.alive {
        let q = Vec3::from_slice(&d.pos[i as usize][..3]);
        let dist = tris
            .iter()
            .map(|t| common::tri_distance(q, t[0], t[1], t[2]))
            .fold(f32::MAX, f32::min);
        assert!(dist < 1e-3, "a birth {dist} m off the skin at {q}");
        ymin = ymin.min(q.y);
        ymax = ymax.max(q.y);
    }
    assert!(
        ymax - ymin > 0.8 * (hi_y - lo_y),
        "births cover {ymin}..{ymax} of {lo_y}..{hi_y}"
    );
}

/// No drop inside a posed capsule, and some resting on one.
fn rain_rests_on_the_body(
    d: &fluidform::psys::system::StateDump,
    posed: &[fluidform::character::capsules::PosedCapsule],
) {
    let mut resting = 0;
    for &i in &d.alive {
        let q = Vec3::from_slice(&d.pos[i as usize][..3]);
        for c in posed {
            let ab = c.b - c.a;
            let h = ((q - c.a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
            let r = (q - (c.a + h * ab)).length();
            assert!(
                r >= c.r - 1e-4,
                "a drop {r} m from a capsule's axis of radius {}",
                c.r
            );
            resting += (r < c.r + 0.01) as u32;
        }
    }
    assert!(resting > 20, "only {resting} drops rest on the body");
}
