//! Depth sorts, colliders and the alive/dead lists; bad systems; every integrator, sort and draw in a scene.

use super::*;

/// View depth of a point.
fn depth(cam: &Camera, p: Vec3) -> f32 {
    (cam.view_proj() * p.extend(1.0)).w
}

/// A ballistic system with `integrator`, sorted by `sort` every frame for 30 frames: the
/// drawn slots are the live ones, back to front.
fn sorted_back_to_front(
    ctx: &Context,
    passes: &Passes,
    cam: &Camera,
    integrator: Integrator,
    sort: SortAlgo,
) {
    let cells = fluidform::psys::system::DEPTH_CELLS as f32;
    let mut spec = ballistic(integrator, 3000);
    spec.sort = Some(sort);
    spec.emitter.rate = Some(Vary {
        mean: 150.0,
        variance: 50.0,
    });
    spec.particle.life = Vary {
        mean: 0.25,
        variance: 0.1,
    };
    let mut s = ParticleSystem::new(ctx, passes, &spec, 0, 11).unwrap();
    let dt = 1.0 / 60.0;
    let last = 30u64;
    ctx.one_shot(|cmd| {
        for k in 0..=last {
            let f = frame(cam, k, dt);
            s.record_step(ctx, cmd, &mut Labels, passes, &f);
            s.record_sort(ctx, cmd, &mut Labels, passes, &f).unwrap();
        }
    })
    .unwrap();
    let d = s.read(ctx).unwrap();
    let (_, order) = s.read_sorted(ctx).unwrap();
    let t = s.time_now();
    let g = Vec3::new(0.0, -9.81, 0.0);
    let drawn: Vec<u32> = order
        .iter()
        .copied()
        .take_while(|&x| x != u32::MAX)
        .collect();
    assert!(
        order[drawn.len()..].iter().all(|&x| x == u32::MAX),
        "{sort:?}: slots after the end"
    );
    let pos = |slot: u32| {
        let (p, v) = (d.pos[slot as usize], d.vel[slot as usize]);
        match integrator {
            Integrator::Closed => closed_pos(
                Vec3::from_slice(&p[..3]),
                Vec3::from_slice(&v[..3]),
                g,
                (t - p[3] as f64) as f32,
            ),
            _ => Vec3::from_slice(&p[..3]),
        }
    };
    // The drawn set is exactly the live particles.
    let mut a: Vec<u32> = drawn.clone();
    let mut b: Vec<u32> = match integrator {
        Integrator::Closed => d.live_closed(t),
        _ => d.alive.clone(),
    };
    a.sort();
    b.sort();
    assert!(a.len() > 500, "{integrator:?}/{sort:?}: {} drawn", a.len());
    assert_eq!(
        a, b,
        "{integrator:?}/{sort:?}: drawn slots are the live ones"
    );
    // Counting: one log-depth cell of slack.
    let slack = match sort {
        SortAlgo::Counting => 1.0 + 2.0 * (cam.far / cam.near).ln() / cells,
        _ => 1.0 + 1e-6,
    };
    for w in drawn.windows(2) {
        let (d0, d1) = (depth(cam, pos(w[0])), depth(cam, pos(w[1])));
        assert!(
            d1 <= d0 * slack,
            "{integrator:?}/{sort:?}: depth {d1} after {d0}"
        );
    }
    s.destroy(ctx);
}

#[test]
fn sprites_are_back_to_front_after_every_sort() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    for (integrator, sort) in [
        (Integrator::Euler, SortAlgo::OddEven),
        (Integrator::Euler, SortAlgo::Bitonic),
        (Integrator::Euler, SortAlgo::Counting),
        (Integrator::Verlet, SortAlgo::Counting),
        (Integrator::Closed, SortAlgo::OddEven),
        (Integrator::Closed, SortAlgo::Counting),
    ] {
        sorted_back_to_front(&ctx, &passes, &cam, integrator, sort);
    }
    let mut passes = passes;
    passes.destroy(&ctx);
    finish(&ctx);
}

#[test]
fn no_particle_passes_a_collider_and_the_lists_partition_the_slots() {
    let ctx = common::ctx();
    // The subgroup-aggregated appends where the device has them, and the plain ones.
    for subgroups in [false, ctx.info.subgroup_arithmetic] {
        colliders_and_lists(&ctx, subgroups);
    }
    finish(&ctx);
}

fn colliders_and_lists(ctx: &Context, subgroups: bool) {
    let passes = Passes::with_subgroups(ctx, subgroups).unwrap();
    let cam = cam();
    let plane = ColliderSpec::ground(0.0, 0.5, 0.2);
    let container = ColliderSpec {
        kind: ColliderKind::Sphere,
        centre: [0.0, 1.0, 0.0],
        radius: 1.5,
        inside: true,
        ..plane.clone()
    };
    let ball = ColliderSpec {
        kind: ColliderKind::Sphere,
        centre: [0.6, 0.4, 0.0],
        radius: 0.3,
        kill: true,
        ..plane.clone()
    };
    for integrator in [Integrator::Euler, Integrator::Verlet] {
        let mut spec = ballistic(integrator, 700);
        spec.emitter.rate = Some(Vary {
            mean: 60.0,
            variance: 30.0,
        });
        spec.particle.velocity = Vary {
            mean: [0.0, -3.0, 0.0],
            variance: [4.0, 4.0, 4.0],
        };
        spec.particle.life = Vary {
            mean: 1.5,
            variance: 1.0,
        };
        spec.collider = vec![plane.clone(), container.clone(), ball.clone()];
        spec.death.max_distance = Some(1.4);
        let mut s = ParticleSystem::new(ctx, &passes, &spec, 0, 5).unwrap();
        let dt = 1.0 / 60.0;
        for chunk in 0..12 {
            ctx.one_shot(|cmd| {
                for k in chunk * 10..chunk * 10 + 10 {
                    s.record_step(ctx, cmd, &mut Labels, &passes, &frame(&cam, k, dt));
                }
            })
            .unwrap();
            let d = s.read(ctx).unwrap();
            partitions(&d.alive, &d.dead, 700)
                .unwrap_or_else(|e| panic!("{integrator:?} frame {}: {e}", chunk * 10 + 9));
            for &slot in &d.alive {
                let p = Vec3::from_slice(&d.pos[slot as usize][..3]);
                assert!(p.y >= -1e-5, "{integrator:?}: below the plane at {p}");
                assert!(
                    (p - Vec3::new(0.0, 1.0, 0.0)).length() <= 1.5 + 1e-4,
                    "{integrator:?}: out of the container at {p}"
                );
            }
            let c = d.counters;
            assert_eq!(c.births as u64 - c.deaths(), d.alive.len() as u64);
        }
        let c = s.read_counters(ctx).unwrap();
        assert!(
            c.refused > 0,
            "{integrator:?}: the budget of 700 was reached"
        );
        assert!(
            c.died_life > 0 && c.died_collision > 0 && c.died_distance > 0,
            "{integrator:?}: {c:?}"
        );
        s.destroy(ctx);
    }
    let mut passes = passes;
    passes.destroy(ctx);
}

#[test]
fn bad_systems_are_clear_errors() {
    let mut s = ballistic(Integrator::Closed, 64);
    s.collider.push(ColliderSpec::ground(0.0, 0.5, 0.2));
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("closed") && e.contains("collider"), "{e}");
    let mut s = ballistic(Integrator::Euler, 64);
    s.particle.life.variance = 200.0;
    assert!(s.validate().unwrap_err().to_string().contains("life"));
    let mut s = ballistic(Integrator::Euler, 64);
    s.draw = Some(SpriteMode::Points);
    s.sort = Some(SortAlgo::Bitonic);
    assert!(s.validate().unwrap_err().to_string().contains("no sort"));
    // Events: a collision event needs a collider; none with the closed form.
    let mut s = ballistic(Integrator::Euler, 64);
    s.event.push(EventSpec {
        on: EventKind::Collision,
        spawn: "x".into(),
        count: Vary {
            mean: 1.0,
            variance: 0.0,
        },
        inherit: 0.0,
        keep_parent: false,
        along_normal: true,
    });
    assert!(s.validate().unwrap_err().to_string().contains("collider"));
    s.event[0].on = EventKind::Death;
    s.event[0].count.mean = 100.0;
    assert!(s.validate().unwrap_err().to_string().contains("count"));
    s.event[0].count.mean = 2.0;
    s.integrator = Some(Integrator::Closed);
    assert!(s.validate().unwrap_err().to_string().contains("event"));
    // Scenes: --sort for points only, closed with forces, spawns of unknown systems.
    let fw = format!("{}/tests/scenes/fireworks.toml", env!("CARGO_MANIFEST_DIR"));
    let mut scene = ParticleScene::find(&fw).unwrap().unwrap();
    let mut body = scene.clone();
    body.system[0].emitter.shape = Shape::Mesh;
    let e = body.validate().unwrap_err().to_string();
    assert!(e.contains("no [character]"), "{e}");
    scene.system[0].event[0].spawn = "nothing".into();
    let e = scene.validate().unwrap_err().to_string();
    assert!(e.contains("'nothing'"), "{e}");
    let smoke = ParticleScene::built_in("smoke").unwrap();
    let e = smoke
        .with_switches(Some(Integrator::Closed), None, None, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("force"), "{e}");
    let flock = ParticleScene::built_in("flock").unwrap();
    let e = flock
        .with_switches(Some(Integrator::Closed), None, None, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("closed"), "{e}");
}

#[test]
fn particle_scenes_run_with_every_integrator_sort_and_draw() {
    let dir = tempfile::tempdir().unwrap();
    let file = format!("{}/tests/scenes/sparks.toml", env!("CARGO_MANIFEST_DIR"));
    let fireworks = format!("{}/tests/scenes/fireworks.toml", env!("CARGO_MANIFEST_DIR"));
    for args in [
        vec!["--scene", "fountain"],
        vec![
            "--scene",
            "fountain",
            "--integrator",
            "verlet",
            "--sort",
            "bitonic",
            "--particles",
            "4096",
        ],
        vec!["--scene", "smoke", "--sort", "none"],
        vec![
            "--scene",
            file.as_str(),
            "--integrator",
            "closed",
            "--sort",
            "odd-even",
        ],
        vec!["--scene", file.as_str(), "--draw", "points"],
        vec!["--scene", fireworks.as_str(), "--frames", "90"],
        vec![
            "--scene",
            "flock",
            "--particles",
            "512",
            "--integrator",
            "verlet",
        ],
        vec!["--scene", "rain", "--particles", "2048", "--frames", "12"],
    ] {
        let out = dir.path().join("run");
        let frames = if args.contains(&"--frames") {
            vec![]
        } else {
            vec!["--frames", "4"]
        };
        let mut all = vec![
            "run",
            "--save-every",
            "3",
            "--validation",
            "--width",
            "96",
            "--height",
            "64",
            "--quiet",
        ];
        all.extend(&args);
        all.extend(&frames);
        all.extend(["--out", out.to_str().unwrap()]);
        let o = fluidform(&all);
        assert!(o.status.success(), "{args:?}: {}", text(&o));
        let sum: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        let systems = sum["stats"]["systems"].as_array().unwrap();
        // (Sub-systems are born by events only: the first system has an emitter.)
        assert!(
            systems[0]["births"].as_u64().unwrap() > 0,
            "{args:?}: {systems:?}"
        );
        assert!(out.join("frame_0003.png").exists());
    }
}

/// A malformed scene file, a closed form with state, a switch the scene does not take,
/// a sort of opaque points: one clear error each, no panic.
#[test]
fn bad_particle_scenes_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let file = format!("{}/tests/scenes/sparks.toml", env!("CARGO_MANIFEST_DIR"));
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[camera]\neye = [0, 1, 4]\ntarget = [0, 1, 0]\n[[system]]\nname = \"a\"\ncapacity = 0x\n",
    )
    .unwrap();
    for (args, says) in [
        (vec!["--scene", bad.to_str().unwrap()], "bad.toml: line 6"),
        (
            vec!["--scene", "smoke", "--integrator", "closed"],
            "no closed form",
        ),
        (
            vec!["--scene", "fountain", "--list", "abuffer"],
            "--list does not apply",
        ),
        (
            vec![
                "--scene",
                file.as_str(),
                "--draw",
                "points",
                "--sort",
                "bitonic",
            ],
            "opaque points",
        ),
    ] {
        let mut all = vec![
            "run",
            "--frames",
            "1",
            "--out",
            dir.path().to_str().unwrap(),
        ];
        all.extend(&args);
        let o = fluidform(&all);
        let t = text(&o);
        assert!(
            !o.status.success() && t.contains(says) && !t.contains("panicked"),
            "{args:?}: {t}"
        );
    }
}
