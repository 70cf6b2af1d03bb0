//! Type changes between systems and boids.

use super::*;

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

/// Rain that turns into splashes on the ground, splashes that burst into mist at death.
fn rain_splash_mist() -> [SystemSpec; 3] {
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
    [rain, splash, mist]
}

/// Every system's lists partition its slots and its counters balance; the type changes
/// create and lose nothing.
fn budget_is_conserved(systems: &[ParticleSystem], d: &[fluidform::psys::system::StateDump]) {
    for (s, d) in systems.iter().zip(d) {
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

#[test]
fn type_changes_conserve_the_budget() {
    let ctx = common::ctx();
    let passes = Passes::new(&ctx).unwrap();
    let cam = cam();
    let specs = rain_splash_mist();
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
        budget_is_conserved(&systems, &d);
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
