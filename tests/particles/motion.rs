//! Integrators against the closed form and energy; emission counts against their statistics.

use super::*;

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
