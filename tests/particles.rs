//! GPU particle systems (seed 003): integrators against the closed form, energy, emission
//! statistics, depth sorts, collisions, and the alive/dead lists.
mod common;
use common::{finish, fluidform, text};
use fluidform::config::{Integrator, SortAlgo, SpriteMode};
use fluidform::gpu::{Context, Labels};
use fluidform::psys::cpu::{attractor_potential, closed_pos, partitions};
use fluidform::psys::spec::*;
use fluidform::psys::{FrameInfo, ParticleSystem, Passes};
use fluidform::render::Camera;
use fluidform::scene::particles::{base_system, emitter, ParticleScene};
use glam::Vec3;

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

#[test]
fn closed_form_equals_verlet_and_euler_with_a_tiny_step() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let n = 256u32;
    let t_end = 0.5f32;
    let g = Vec3::new(0.0, -9.81, 0.0);
    let run = |integrator, dt: f32| {
        let mut s = ParticleSystem::new(&ctx, &passes, &ballistic(integrator, n), 0, 7).unwrap();
        let k = (t_end / dt).round() as u64;
        steps(&ctx, &passes, &mut s, &cam, dt, 0, k, n);
        let d = s.read(&ctx).unwrap();
        let colors: Vec<[f32; 4]> = ctx.readback(s.color_buffer(), 0, n as usize).unwrap();
        s.destroy(&ctx);
        (d, colors)
    };
    // Closed form: the state is p0, v0 and the birth time.
    let (closed, ccol) = run(Integrator::Closed, 1.0 / 60.0);
    let exact: std::collections::HashMap<[u32; 4], Vec3> = (0..n as usize)
        .map(|i| {
            let (p, v) = (closed.pos[i], closed.vel[i]);
            assert_eq!(p[3], 0.0, "born at t = 0");
            (
                key(ccol[i]),
                closed_pos(
                    Vec3::from_slice(&p[..3]),
                    Vec3::from_slice(&v[..3]),
                    g,
                    t_end,
                ),
            )
        })
        .collect();
    assert_eq!(exact.len(), n as usize, "colours identify particles");
    for (integrator, dt, bound) in [
        (Integrator::Verlet, 1.0 / 60.0, 2e-4f32),
        (
            Integrator::Euler,
            1e-4,
            0.5 * 9.81 * 1e-4 * t_end * 1.05 + 1e-4,
        ),
    ] {
        let (d, col) = run(integrator, dt);
        assert_eq!(d.alive.len(), n as usize);
        let mut worst = 0.0f32;
        for &slot in &d.alive {
            let p = Vec3::from_slice(&d.pos[slot as usize][..3]);
            let e = exact[&key(col[slot as usize])];
            worst = worst.max((p - e).length());
            assert!((d.pos[slot as usize][3] - t_end).abs() < 1e-3, "age");
        }
        assert!(
            worst <= bound,
            "{integrator:?} at dt {dt}: {worst} m from the closed form (bound {bound})"
        );
    }
    // Euler's error is first order in dt: a coarse step is visibly off.
    let (d, col) = run(Integrator::Euler, 1.0 / 60.0);
    let worst = d
        .alive
        .iter()
        .map(|&s| {
            (Vec3::from_slice(&d.pos[s as usize][..3]) - exact[&key(col[s as usize])]).length()
        })
        .fold(0.0f32, f32::max);
    assert!(
        worst > 0.02,
        "euler at 1/60 s should miss by ~g dt t / 2 = 0.04 m, got {worst}"
    );
    let mut passes = passes;
    passes.destroy(&ctx);
    finish(&ctx);
}

#[test]
fn verlet_conserves_energy_in_an_orbit() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let (strength, eps, r) = (1.0f32, 0.01f32, 0.5f32);
    let speed = (strength * r / (r * r + eps)).sqrt();
    let mut spec = ballistic(Integrator::Verlet, 1);
    spec.emitter = emitter(
        Shape::Point,
        [r, 0.0, 0.0],
        0.0,
        Vary {
            mean: 0.0,
            variance: 0.0,
        },
    );
    spec.particle.velocity = Vary {
        mean: [0.0, 0.0, speed * 0.9],
        variance: [0.0; 3],
    };
    spec.gravity = [0.0; 3];
    spec.force.push(ForceSpec {
        kind: ForceKind::Attractor,
        at: [0.0; 3],
        axis: [0.0, 1.0, 0.0],
        strength,
        eps,
        scale: 1.0,
        speed: 0.0,
    });
    let mut s = ParticleSystem::new(&ctx, &passes, &spec, 0, 1).unwrap();
    let dt = 1.0 / 240.0;
    let energy = |d: &fluidform::psys::system::StateDump| {
        let slot = d.alive[0] as usize;
        let p = Vec3::from_slice(&d.pos[slot][..3]);
        let v = (p - Vec3::from_slice(&d.vel[slot][..3])) / dt;
        0.5 * v.length_squared() as f64 + attractor_potential(p.length(), strength, eps)
    };
    steps(&ctx, &passes, &mut s, &cam, dt, 0, 1, 1);
    let e0 = energy(&s.read(&ctx).unwrap());
    let mut worst = 0.0f64;
    let mut radii = (f32::MAX, 0.0f32);
    for chunk in 0..20 {
        steps(&ctx, &passes, &mut s, &cam, dt, 1 + chunk * 100, 100, 0);
        let d = s.read(&ctx).unwrap();
        assert_eq!(d.alive.len(), 1);
        let rr = Vec3::from_slice(&d.pos[d.alive[0] as usize][..3]).length();
        radii = (radii.0.min(rr), radii.1.max(rr));
        worst = worst.max((energy(&d) - e0).abs() / e0.abs());
    }
    // An eccentric orbit (0.9 of the circular speed) over several periods.
    assert!(
        radii.1 - radii.0 > 0.05,
        "the orbit is eccentric: {radii:?}"
    );
    assert!(
        worst < 0.01,
        "verlet energy drift {worst} of |E0| (bound 1%)"
    );
    s.destroy(&ctx);
    let mut passes = passes;
    passes.destroy(&ctx);
    finish(&ctx);
}

#[test]
fn emitted_counts_match_mean_and_variance() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let (mean, var) = (20.0f32, 10.0f32);
    let mut spec = ballistic(Integrator::Euler, 1 << 15);
    spec.emitter.rate = Some(Vary {
        mean,
        variance: var,
    });
    spec.particle.life = Vary {
        mean: 0.05,
        variance: 0.0,
    };
    let mut s = ParticleSystem::new(&ctx, &passes, &spec, 0, 3).unwrap();
    let frames = 1500u64;
    ctx.one_shot(|cmd| {
        for k in 0..frames {
            s.record_step(&ctx, cmd, &mut Labels, &passes, &frame(&cam, k, 1.0 / 60.0));
        }
    })
    .unwrap();
    let c = s.read_counters(&ctx).unwrap();
    assert_eq!(
        c.births as u64,
        s.births_asked(),
        "the GPU bore every birth drawn"
    );
    assert_eq!(c.refused, 0);
    let m = s.births_sum.0 / frames as f64;
    let v = s.births_sum.1 / frames as f64 - m * m;
    // rand uniform in [-1, 1): variance var^2 / 3, plus the stochastic rounding's (<= 1/4).
    let expect_v = (var * var / 3.0) as f64 + 1.0 / 6.0;
    let se = (expect_v / frames as f64).sqrt();
    assert!(
        (m - mean as f64).abs() < 4.0 * se,
        "mean {m} vs {mean} (se {se})"
    );
    assert!(
        (v / expect_v - 1.0).abs() < 0.12,
        "variance {v} vs {expect_v}"
    );
    // Lives of 3 frames: births and deaths balance.
    assert_eq!(
        c.births as u64 - c.deaths(),
        c.alive[s.drawn() as usize] as u64
    );
    s.destroy(&ctx);
    let mut passes = passes;
    passes.destroy(&ctx);
    finish(&ctx);
}

/// View depth of a point.
fn depth(cam: &Camera, p: Vec3) -> f32 {
    (cam.view_proj() * p.extend(1.0)).w
}

#[test]
fn sprites_are_back_to_front_after_every_sort() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let cells = fluidform::psys::system::DEPTH_CELLS as f32;
    for (integrator, sort) in [
        (Integrator::Euler, SortAlgo::OddEven),
        (Integrator::Euler, SortAlgo::Bitonic),
        (Integrator::Euler, SortAlgo::Counting),
        (Integrator::Verlet, SortAlgo::Counting),
        (Integrator::Closed, SortAlgo::OddEven),
        (Integrator::Closed, SortAlgo::Counting),
    ] {
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
        let mut s = ParticleSystem::new(&ctx, &passes, &spec, 0, 11).unwrap();
        let dt = 1.0 / 60.0;
        let last = 30u64;
        ctx.one_shot(|cmd| {
            for k in 0..=last {
                let f = frame(&cam, k, dt);
                s.record_step(&ctx, cmd, &mut Labels, &passes, &f);
                ctx.barrier(
                    cmd,
                    fluidform::gpu::sync::COMPUTE_WRITE,
                    fluidform::gpu::sync::COMPUTE_READ,
                );
                s.record_sort(&ctx, cmd, &mut Labels, &passes, &f).unwrap();
            }
        })
        .unwrap();
        let d = s.read(&ctx).unwrap();
        let (_, order) = s.read_sorted(&ctx).unwrap();
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
            let (d0, d1) = (depth(&cam, pos(w[0])), depth(&cam, pos(w[1])));
            assert!(
                d1 <= d0 * slack,
                "{integrator:?}/{sort:?}: depth {d1} after {d0}"
            );
        }
        s.destroy(&ctx);
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

/// A system with no emitter births, to be spawned by events.
fn child(name: &str, capacity: u32, life: f32) -> SystemSpec {
    let mut s = ballistic(Integrator::Euler, capacity);
    s.name = name.into();
    s.particle.velocity = Vary {
        mean: [0.0, 1.5, 0.0],
        variance: [0.0, 0.3, 0.0],
    };
    s.particle.spread = 40.0;
    s.particle.life = Vary {
        mean: life,
        variance: 0.5 * life,
    };
    s
}

#[test]
fn type_changes_conserve_the_budget() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let ground = ColliderSpec::ground(0.0, 0.3, 0.2);
    let mut rain = ballistic(Integrator::Euler, 2048);
    rain.name = "rain".into();
    rain.emitter = emitter(
        Shape::Box,
        [0.0, 1.2, 0.0],
        0.5,
        Vary {
            mean: 40.0,
            variance: 10.0,
        },
    );
    rain.particle.velocity = Vary {
        mean: [0.0, -2.0, 0.0],
        variance: [0.2, 0.2, 0.2],
    };
    rain.collider = vec![ground.clone()];
    // On the ground a drop becomes a splash (one child, the parent dies).
    rain.event = vec![EventSpec {
        on: EventKind::Collision,
        spawn: "splash".into(),
        count: Vary {
            mean: 1.0,
            variance: 0.0,
        },
        inherit: 0.2,
        keep_parent: false,
        along_normal: true,
    }];
    // Splashes (too few slots for every drop: refused children are counted) burst into
    // mist at death: mean 2 children, variance 1.
    let mut splash = child("splash", 96, 0.3);
    splash.collider = vec![ground];
    splash.event = vec![EventSpec {
        on: EventKind::Death,
        spawn: "mist".into(),
        count: Vary {
            mean: 2.0,
            variance: 1.0,
        },
        inherit: 0.0,
        keep_parent: false,
        along_normal: true,
    }];
    let mist = child("mist", 8192, 0.2);
    for s in [&mut splash, &mut rain] {
        s.validate().unwrap();
    }
    let specs = [rain, splash, mist];
    let mut systems: Vec<ParticleSystem> = specs
        .iter()
        .enumerate()
        .map(|(i, s)| ParticleSystem::new(&ctx, &passes, s, i as u32, 11).unwrap())
        .collect();
    let dt = 1.0 / 60.0;
    for chunk in 0..10 {
        ctx.one_shot(|cmd| {
            for k in chunk * 12..chunk * 12 + 12 {
                let f = frame(&cam, k, dt);
                fluidform::psys::frame::record_simulation(
                    &ctx,
                    cmd,
                    &mut Labels,
                    &passes,
                    &mut systems,
                    &f,
                )
                .unwrap();
            }
        })
        .unwrap();
        let d: Vec<_> = systems.iter().map(|s| s.read(&ctx).unwrap()).collect();
        for (s, d) in systems.iter().zip(&d) {
            partitions(&d.alive, &d.dead, s.capacity)
                .unwrap_or_else(|e| panic!("{}: {e}", s.spec.name));
            let c = d.counters;
            assert_eq!(
                (c.births + c.spawned) as u64 - c.deaths(),
                d.alive.len() as u64,
                "{}: births + children - deaths = alive ({c:?})",
                s.spec.name
            );
            assert_eq!(c.events_dropped, 0, "{}", s.spec.name);
        }
        let (r, sp, m) = (d[0].counters, d[1].counters, d[2].counters);
        // Every drop that left the rain arrived as a splash or was refused for want of a
        // slot: the type change creates and loses nothing.
        assert_eq!(
            r.died_life + r.died_collision,
            0,
            "drops die only by changing"
        );
        assert_eq!(r.changed, sp.spawned + sp.spawn_refused);
        assert_eq!(sp.births + m.births, 0, "children come from events alone");
        // Each splash that died of age spawned 0..=3 mist children.
        let asked = (m.spawned + m.spawn_refused) as u64;
        assert!(
            asked <= 3 * sp.died_life as u64,
            "{asked} > 3 x {}",
            sp.died_life
        );
        // Children are born where their parent hit the ground: never below it.
        for &slot in &d[1].alive {
            assert!(d[1].pos[slot as usize][1] >= -1e-5);
        }
    }
    let sp = systems[1].read_counters(&ctx).unwrap();
    let m = systems[2].read_counters(&ctx).unwrap();
    assert!(sp.spawned > 100 && sp.spawn_refused > 0, "{sp:?}");
    let per = (m.spawned + m.spawn_refused) as f64 / sp.died_life as f64;
    assert!(
        (per - 2.0).abs() < 0.25,
        "mist children per splash death {per:.3}, mean 2"
    );
    for s in &mut systems {
        s.destroy(&ctx);
    }
    let mut passes = passes;
    passes.destroy(&ctx);
    finish(&ctx);
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

#[test]
fn boids_keep_their_count_and_the_speed_limit() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let scene = ParticleScene::built_in("flock")
        .unwrap()
        .with_switches(None, None, None, Some(1024))
        .unwrap();
    let spec = scene.system[0].clone();
    let b = spec.boids.clone().unwrap();
    let mut s = ParticleSystem::new(&ctx, &passes, &spec, 0, 3).unwrap();
    let dt = scene.dt;
    let polarisation = |d: &fluidform::psys::system::StateDump| {
        let vs: Vec<Vec3> = d
            .alive
            .iter()
            .map(|&i| Vec3::from_slice(&d.vel[i as usize][..3]))
            .collect();
        let sum: Vec3 = vs.iter().sum();
        sum.length() / vs.iter().map(|v| v.length()).sum::<f32>()
    };
    let mut first = None;
    for chunk in 0..8u64 {
        ctx.one_shot(|cmd| {
            for k in chunk * 30..chunk * 30 + 30 {
                s.record_step(&ctx, cmd, &mut Labels, &passes, &frame(&cam, k, dt));
            }
        })
        .unwrap();
        let d = s.read(&ctx).unwrap();
        assert_eq!(d.alive.len(), 1024, "the flock keeps its count");
        assert_eq!(d.counters.deaths(), 0);
        partitions(&d.alive, &d.dead, 1024).unwrap();
        for &i in &d.alive {
            let (p, v) = (d.pos[i as usize], Vec3::from_slice(&d.vel[i as usize][..3]));
            let speed = v.length();
            assert!(
                speed <= b.max_speed * 1.0001 && speed >= b.min_speed * 0.9999,
                "speed {speed} outside [{}, {}]",
                b.min_speed,
                b.max_speed
            );
            for k in 0..3 {
                assert!(
                    p[k] >= b.bounds[0][k] - 1e-4 && p[k] <= b.bounds[1][k] + 1e-4,
                    "{p:?} left the room"
                );
            }
        }
        let pol = polarisation(&d);
        eprintln!("frame {}: polarisation {pol:.3}", chunk * 30 + 29);
        first.get_or_insert(pol);
    }
    // Alignment orders the flock: velocities started random (polarisation ~0).
    let last = polarisation(&s.read(&ctx).unwrap());
    assert!(
        last > first.unwrap() + 0.15,
        "polarisation {:.3} -> {last:.3}: the boids do not align",
        first.unwrap()
    );
    // The GPU's steering against the CPU's from the same state.
    let d = s.read(&ctx).unwrap();
    ctx.one_shot(|cmd| s.record_step(&ctx, cmd, &mut Labels, &passes, &frame(&cam, 240, dt)))
        .unwrap();
    let steer = s.read_steer(&ctx).unwrap();
    let mut worst = 0.0f32;
    let mut count_mismatch = 0;
    for &i in &d.alive {
        let (a, n) = cpu_steer(&spec, &d, i, &[]);
        let g = steer[i as usize];
        count_mismatch += (g[3] as u32 != n) as u32;
        worst = worst.max((Vec3::from_slice(&g[..3]) - a).length() / (1.0 + a.length()));
    }
    // Neighbours exactly at the radius may round either way.
    assert!(
        count_mismatch <= 2,
        "{count_mismatch} boids saw other flockmates"
    );
    assert!(worst < 2e-3, "steering differs from the CPU's by {worst}");
    s.destroy(&ctx);
    let mut passes = passes;
    passes.destroy(&ctx);
    finish(&ctx);
}

#[test]
fn mesh_emitter_births_lie_on_the_skin_and_the_body_collides() {
    use fluidform::character::capsules;
    use fluidform::config::{ShowMesh, Skinning};
    use fluidform::psys::character::CharacterLink;
    use fluidform::scene::character::{CharacterDesc, SceneCharacter};
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
    let tris: Vec<[Vec3; 3]> = ch
        .ch
        .mesh
        .indices
        .chunks_exact(3)
        .map(|t| [p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]])
        .collect();
    let (lo_y, hi_y) = p
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v.y), h.max(v.y)));
    let d = systems[0].read(&ctx).unwrap();
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
    let posed: Vec<_> = capsules::of(&ch.ch)
        .iter()
        .map(|c| c.posed(&mats))
        .collect();
    let d = systems[1].read(&ctx).unwrap();
    let mut resting = 0;
    for &i in &d.alive {
        let q = Vec3::from_slice(&d.pos[i as usize][..3]);
        for c in &posed {
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

/// A fluid block at rest seen from the front, and a sheet of still particles (drawn as
/// `draw`) across the view at depth `z` (none: no system).
fn sheet_scene(draw: &str, z: Option<f32>) -> String {
    let mut s = String::from(
        r#"name = "sheet"
frames = 1
[domain]
min = [0.0, 0.0, 0.0]
max = [0.4, 0.4, 0.4]
[fluid]
eos = "tait"
sound_speed = 20.0
clamp_negative_pressure = true
dt = 0.0005
substeps = 2
[[blocks]]
min = [0.1, 0.0, 0.1]
max = [0.3, 0.2, 0.3]
[camera]
eye = [0.2, 0.15, 1.6]
target = [0.2, 0.1, 0.2]
fov = 45.0
[look]
material = "phong"
tank = false
"#,
    );
    if let Some(z) = z {
        let (sort, px) = match draw {
            "points" => ("", "point_px = 6.0"),
            _ => ("sort = \"counting\"", ""),
        };
        s += &format!(
            r#"
[[system]]
name = "sheet"
capacity = 8192
draw = "{draw}"
{sort}
{px}
gravity = [0.0, 0.0, 0.0]
[system.emitter]
shape = "box"
centre = [0.2, 0.1, {z}]
half = [0.6, 0.5, 0.0]
burst = 6000
[system.particle]
size = {{ mean = 0.06, variance = 0.0 }}
life = {{ mean = 100.0, variance = 0.0 }}
color = {{ mean = [1.0, 0.2, 0.1, 1.0], variance = [0.0, 0.0, 0.0, 0.0] }}
"#
        );
    }
    s
}

#[test]
fn particles_composite_with_the_metaball_fluid_by_depth() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (96u32, 64u32);
    let render = |name: &str, toml: String| -> image::RgbaImage {
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, toml).unwrap();
        let out = dir.path().join(name);
        let (ws, hs) = (w.to_string(), h.to_string());
        let o = fluidform(&[
            "run",
            "--scene",
            file.to_str().unwrap(),
            "--validation",
            "--quiet",
            "--width",
            &ws,
            "--height",
            &hs,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", text(&o));
        if name != "fluid" {
            let sum = common::summary(&out);
            let sys = &sum["stats"]["particle_systems"][0];
            assert_eq!(sys["births"].as_u64(), Some(6000), "{name}: {sys}");
            assert_eq!(sys["alive"].as_u64(), Some(6000), "{name}: {sys}");
        }
        image::open(out.join("frame_0000.png")).unwrap().to_rgba8()
    };
    // Pixels of a world point, as the march maps them (row 0 at NDC y = -1).
    let cam = Camera::look_at(
        Vec3::new(0.2, 0.15, 1.6),
        Vec3::new(0.2, 0.1, 0.2),
        45.0,
        w as f32 / h as f32,
    );
    let pixel = |p: Vec3| {
        let c = cam.view_proj() * p.extend(1.0);
        let ndc = c.truncate() / c.w;
        let x = ((ndc.x + 1.0) * 0.5 * w as f32 - 0.5).round() as i32;
        let y = ((ndc.y + 1.0) * 0.5 * h as f32 - 0.5).round() as i32;
        assert!(
            x >= 2 && y >= 2 && x < w as i32 - 2 && y < h as i32 - 2,
            "{p} -> {x},{y}"
        );
        (x, y)
    };
    // Mean channel difference of two frames over the 5 x 5 pixels around `at`.
    let diff = |a: &image::RgbaImage, b: &image::RgbaImage, (x, y): (i32, i32)| {
        let mut sum = 0.0;
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (pa, pb) = (
                    a.get_pixel((x + dx) as u32, (y + dy) as u32),
                    b.get_pixel((x + dx) as u32, (y + dy) as u32),
                );
                sum += (0..3)
                    .map(|k| (pa[k] as f32 - pb[k] as f32).abs())
                    .sum::<f32>();
            }
        }
        sum / 75.0
    };
    let fluid = render("fluid", sheet_scene("sprites", None));
    // The block's front face, and the sheet beside the block.
    let (behind, front) = (-0.3, 0.9);
    let water = pixel(Vec3::new(0.2, 0.08, 0.3));
    let beside = pixel(Vec3::new(-0.25, 0.45, behind));
    for draw in ["sprites", "points"] {
        let back = render(&format!("{draw}-behind"), sheet_scene(draw, Some(behind)));
        let over = render(&format!("{draw}-front"), sheet_scene(draw, Some(front)));
        // Behind the water: hidden by it, seen beside it; in front: over it.
        let (hidden, seen, covers) = (
            diff(&back, &fluid, water),
            diff(&back, &fluid, beside),
            diff(&over, &fluid, water),
        );
        eprintln!(
            "{draw}: behind the water {hidden:.2}, beside it {seen:.2}, in front {covers:.2}"
        );
        assert!(
            hidden < 2.0,
            "{draw}: the sheet behind shows through the water ({hidden})"
        );
        assert!(
            seen > 30.0,
            "{draw}: the sheet behind is missing beside the water ({seen})"
        );
        assert!(
            covers > 30.0,
            "{draw}: the sheet in front does not cover the water ({covers})"
        );
    }
}

#[test]
fn sph_scenes_play_particle_systems_and_refuse_what_they_cannot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spray");
    let spray = format!("{}/tests/scenes/spray.toml", env!("CARGO_MANIFEST_DIR"));
    let o = fluidform(&[
        "run",
        "--scene",
        &spray,
        "--frames",
        "3",
        "--width",
        "64",
        "--height",
        "48",
        "--validation",
        "--quiet",
        "--integrator",
        "verlet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let sum = common::summary(&out);
    let systems = sum["stats"]["particle_systems"].as_array().unwrap();
    assert_eq!(systems.len(), 2);
    assert!(systems[0]["births"].as_u64().unwrap() > 0, "{systems:?}");
    assert_eq!(systems[1]["alive"].as_u64(), Some(300), "{systems:?}");
    assert!(systems.iter().all(|s| s["integrator"] == "verlet"));
    assert!(sum["stats"]["particles"].as_u64().unwrap() > 1000);
    // A system on the character, and systems with no fluid, are refused by name.
    let body = sheet_scene("sprites", Some(0.0)) + "[[system.collider]]\nkind = \"character\"\n";
    let alone = "name = \"alone\"\n[domain]\nmin = [-1.0, 0.0, -1.0]\nmax = [1.0, 2.0, 1.0]\n\
                 [character]\nfile = \"builtin:walker\"\n"
        .to_string()
        + &sheet_scene("sprites", Some(0.0))[sheet_scene("sprites", None).len()..];
    for (name, toml, expect) in [
        ("body", body, "do not reach yet"),
        ("alone", alone, "without fluid"),
    ] {
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, toml).unwrap();
        let o = fluidform(&["run", "--scene", file.to_str().unwrap(), "--quiet"]);
        assert!(!o.status.success(), "{name} ran");
        assert!(text(&o).contains(expect), "{name}: {}", text(&o));
        assert_eq!(text(&o).trim().lines().count(), 1, "{}", text(&o));
    }
}
