//! SPH on the GPU against the f64 CPU reference, physics invariants, boundaries, scenes.
#[path = "../common/mod.rs"]
mod common;
use fluidform::gpu::{Context, Labels};
use fluidform::kinds::{Neighbors, SortAlgo};
use fluidform::scene::schema::{Ball, Block, Domain, Particles, Scene};
use fluidform::sph::cpu;
use fluidform::sph::params::Collider;
use fluidform::sph::{Eos, FluidParams, SphSolver};

const STRATEGIES: [(Neighbors, SortAlgo); 4] = [
    (Neighbors::Grid, SortAlgo::Counting),
    (Neighbors::Hash, SortAlgo::Bitonic),
    (Neighbors::Hash, SortAlgo::OddEven),
    (Neighbors::Morton, SortAlgo::OddEven),
];

mod kernels;
mod scenes;
mod solvers;

fn block_scene(fluid: FluidParams) -> Scene {
    Scene {
        name: "test block".into(),
        domain: Domain {
            min: [0.0; 3],
            max: [0.4, 0.4, 0.4],
        },
        fluid,
        blocks: vec![Block {
            min: [0.05, 0.0, 0.05],
            max: [0.3, 0.2, 0.25],
            group: 0,
            color: [0.2, 0.5, 1.0],
            velocity: [0.0; 3],
        }],
        balls: vec![Ball {
            center: [0.3, 0.3, 0.3],
            radius: 0.05,
            group: 1,
            color: [1.0, 0.5, 0.1],
            velocity: [0.0, -0.5, 0.0],
        }],
        colliders: vec![],
        camera: None,
        frames: 1,
        look: Default::default(),
        character: None,
        control: None,
        targets: vec![],
        timeline: vec![],
        emission: None,
        system: vec![],
        pool: None,
    }
}

/// Random points (no two closer than a third of the rest spacing) with random velocities.
fn random_particles(scene: &Scene, n: usize, seed: u64) -> Particles {
    let s = scene.fluid.spacing();
    let side = s * (n as f32).cbrt() * 1.1;
    common::random_particles(s, n, [0.05, 0.02, 0.05], side, 0.5, seed)
}

/// One arrange + density + forces on the GPU; compare with the reference on the same
/// (sorted) particles. Returns the largest relative errors (density, acceleration).
fn compare(ctx: &Context, solver: &mut SphSolver, scene: &Scene, parts: &Particles) -> (f64, f64) {
    let mut st = solver.state(ctx, scene, parts).unwrap();
    ctx.one_shot(|cmd| {
        solver.record_params(ctx, cmd, &st);
        solver.record_arrange(ctx, cmd, &mut Labels, &mut st)?;
        solver.record_density(ctx, cmd, &mut Labels, &st);
        solver.record_forces(ctx, cmd, &mut Labels, &st);
        Ok::<_, fluidform::Error>(())
    })
    .unwrap()
    .unwrap();
    let d = st.read(ctx).unwrap();
    st.destroy(ctx);
    let b =
        fluidform::sph::boundary::Boundary::new(&scene.fluid, scene.domain.min, scene.domain.max)
            .with_colliders(&scene.colliders)
            .unwrap();
    let r = cpu::evaluate(&scene.fluid, &b, &d.pos, &d.vel);
    let n = d.pos.len();
    let mean_a = r
        .acc
        .iter()
        .map(|a| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt())
        .sum::<f64>()
        / n as f64;
    let (mut err_rho, mut err_a) = (0.0f64, 0.0f64);
    let l = scene.fluid.tension_threshold as f64;
    for i in 0..n {
        err_rho = err_rho.max((d.rho_p[i][0] as f64 - r.density[i]).abs() / r.density[i]);
        // Surface tension switches on at |grad c| = l: skip particles right at the switch.
        if (r.color_grad[i] - l).abs() < 1e-2 * l {
            continue;
        }
        let da: f64 = (0..3)
            .map(|k| (d.acc[i][k] as f64 - r.acc[i][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let a = (0..3).map(|k| r.acc[i][k].powi(2)).sum::<f64>().sqrt();
        err_a = err_a.max(da / a.max(mean_a));
    }
    (err_rho, err_a)
}

#[test]
fn gpu_density_and_acceleration_match_f64_reference() {
    let ctx = common::ctx();
    let ideal = FluidParams::default();
    let tait = FluidParams {
        eos: Eos::Tait,
        sound_speed: 20.0,
        ..FluidParams::default()
    };
    for (strategy, sort) in STRATEGIES {
        let mut solver = SphSolver::new(&ctx, strategy, Some(sort)).unwrap();
        // The walls and colliders count in the densities and push back (boundary.glsl).
        let obstacles = vec![
            Collider::Sphere {
                center: [0.17, 0.1, 0.15],
                radius: 0.04,
                velocity: [0.0; 3],
            },
            Collider::Capsule {
                a: [0.05, 0.17, 0.05],
                b: [0.3, 0.19, 0.25],
                radius: 0.02,
                velocity: [0.1, 0.0, 0.0],
            },
            Collider::Plane {
                normal: [0.3, 1.0, 0.0],
                offset: 0.03,
                velocity: [0.0; 3],
            },
        ];
        for (what, fluid, colliders) in [
            ("kelager", ideal.clone(), vec![]),
            ("tait", tait.clone(), vec![]),
            ("tait, colliders", tait.clone(), obstacles),
        ] {
            let mut scene = block_scene(fluid);
            scene.colliders = colliders;
            let lattice = scene.particles(3);
            let random = random_particles(&scene, 1500, 9);
            for (kind, parts) in [("lattice", &lattice), ("random", &random)] {
                let (e_rho, e_a) = compare(&ctx, &mut solver, &scene, parts);
                assert!(
                    e_rho < 1e-3,
                    "{strategy:?}/{sort:?} {what} {kind}: density error {e_rho:e}"
                );
                assert!(
                    e_a < 1e-3,
                    "{strategy:?}/{sort:?} {what} {kind}: acceleration error {e_a:e}"
                );
            }
        }
        solver.destroy(&ctx);
    }
    common::finish(&ctx);
}

#[test]
fn internal_forces_conserve_momentum() {
    // Pressure and viscosity are antisymmetric between pairs: without gravity, tension and
    // walls, sum_i m a_i = 0 (relative to sum_i m |a_i|).
    let ctx = common::ctx();
    let fluid = FluidParams {
        gravity: [0.0; 3],
        surface_tension: 0.0,
        ..FluidParams::default()
    };
    let scene = block_scene(fluid);
    let parts = random_particles(&scene, 1200, 4);
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, None).unwrap();
    let mut st = solver.state(&ctx, &scene, &parts).unwrap();
    ctx.one_shot(|cmd| {
        solver.record_params(&ctx, cmd, &st);
        solver
            .record_arrange(&ctx, cmd, &mut Labels, &mut st)
            .unwrap();
        solver.record_density(&ctx, cmd, &mut Labels, &st);
        solver.record_forces(&ctx, cmd, &mut Labels, &st);
    })
    .unwrap();
    let d = st.read(&ctx).unwrap();
    let mut total = [0.0f64; 3];
    let mut abs = 0.0f64;
    // Pair forces m a_ij = -m^2 (p_i + p_j) / (2 rho_i rho_j) grad W_ij (and the viscous
    // analogue) are antisymmetric, so the sum of m a_i vanishes (equal masses: of a_i).
    for a in &d.acc {
        for k in 0..3 {
            total[k] += a[k] as f64;
        }
        abs += (0..3).map(|k| (a[k] as f64).powi(2)).sum::<f64>().sqrt();
    }
    let net = (total[0].powi(2) + total[1].powi(2) + total[2].powi(2)).sqrt();
    assert!(abs > 0.0);
    assert!(
        net < 1e-3 * abs,
        "net force {net:e} vs total magnitude {abs:e}"
    );
    st.destroy(&ctx);
    solver.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn kernels_the_solver_uploads_are_normalised() {
    // Integrate the kernels with the constants the solver uploads (SphGpuParams, f32) over
    // their support on a fine lattice: W_poly6 and W_spiky integrate to 1 within 0.5%.
    let f = FluidParams::default();
    let p = fluidform::sph::params::SphGpuParams::new(&f, [0.0; 3], [1.0; 3], f.dt, 0);
    let h = p.h as f64;
    let c = p.poly6 as f64;
    // W_spiky = -spiky_grad / 3 (h - r)^3, whose gradient is the one the forces use.
    let spiky = -(p.spiky_grad as f64) / 3.0;
    let steps = 80;
    let dx = 2.0 * h / steps as f64;
    let (mut sum, mut sum_spiky) = (0.0, 0.0);
    for i in 0..steps {
        for j in 0..steps {
            for k in 0..steps {
                let q = [
                    (i as f64 + 0.5) * dx - h,
                    (j as f64 + 0.5) * dx - h,
                    (k as f64 + 0.5) * dx - h,
                ];
                let r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
                if r2 < h * h {
                    sum += c * (h * h - r2).powi(3) * dx * dx * dx;
                    sum_spiky += spiky * (h - r2.sqrt()).powi(3) * dx * dx * dx;
                }
            }
        }
    }
    assert!((sum - 1.0).abs() < 5e-3, "poly6 integral {sum}");
    assert!((sum_spiky - 1.0).abs() < 5e-3, "spiky integral {sum_spiky}");
    // grad W_poly6 = -6 poly6 r (h^2 - r^2)^2, and the viscosity Laplacian's constant is
    // the spiky gradient's magnitude (both 45 / (pi h^6)), as uploaded.
    assert!(((p.poly6_grad / p.poly6) as f64 + 6.0).abs() < 1e-5);
    assert!(((p.visc_lap / p.spiky_grad) as f64 + 1.0).abs() < 1e-6);
    // The rest lattice of Kelager's water has a density near rho_0 (about 20 neighbours).
    let s = f.spacing() as f64;
    let mut rho = 0.0;
    for i in -3i32..=3 {
        for j in -3i32..=3 {
            for k in -3i32..=3 {
                let r2 = (i * i + j * j + k * k) as f64 * s * s;
                if r2 < h * h {
                    rho += f.mass as f64 * c * (h * h - r2).powi(3);
                }
            }
        }
    }
    assert!(
        (rho / f.rest_density as f64 - 1.0).abs() < 0.1,
        "lattice density {rho}"
    );
}

fn run_steps(
    ctx: &Context,
    scene: &Scene,
    steps: u32,
    strategy: Neighbors,
    sort: SortAlgo,
) -> fluidform::sph::solver::StateDump {
    let parts = scene.particles(1);
    let mut solver = SphSolver::new(ctx, strategy, Some(sort)).unwrap();
    let mut st = solver.state(ctx, scene, &parts).unwrap();
    for _ in 0..steps.div_ceil(50) {
        ctx.one_shot(|cmd| {
            for _ in 0..50 {
                solver.record_step(ctx, cmd, &mut Labels, &mut st).unwrap();
            }
        })
        .unwrap();
    }
    let d = st.read(ctx).unwrap();
    st.destroy(ctx);
    solver.destroy(ctx);
    d
}

fn assert_sane(d: &fluidform::sph::solver::StateDump, scene: &Scene, what: &str) {
    let (lo, hi) = (scene.domain.min, scene.domain.max);
    for (i, p) in d.pos.iter().enumerate() {
        for k in 0..3 {
            assert!(p[k].is_finite(), "{what}: particle {i} is NaN");
            assert!(
                p[k] >= lo[k] && p[k] <= hi[k],
                "{what}: particle {i} left the domain: {p:?}"
            );
        }
        assert!(
            d.vel[i].iter().all(|v| v.is_finite()),
            "{what}: velocity {i} NaN"
        );
    }
}

/// Two balls of different sizes colliding head-on without gravity, far from every wall:
/// the total momentum (equal masses: the sum of the velocities) stays what it was, with
/// every solver. Pressure, viscosity, DFSPH's and PCISPH's pressure forces, PBF's position
/// corrections and XSPH all act in equal and opposite pairs; surface tension (Kelager's
/// colour-field force) and PBF's vorticity confinement do not, so both are off.
#[test]
fn every_solver_conserves_momentum_without_walls() {
    use fluidform::sph::Solver;
    let ctx = common::ctx();
    for solver_kind in [Solver::Wcsph, Solver::Pcisph, Solver::Dfsph, Solver::Pbf] {
        let mut fluid = FluidParams {
            gravity: [0.0; 3],
            surface_tension: 0.0,
            dt: 0.001,
            solver: solver_kind,
            ..FluidParams::default()
        };
        fluid.pbf.vorticity = 0.0;
        let ball = |center: [f32; 3], radius: f32, vx: f32, group: u32| Ball {
            center,
            radius,
            group,
            color: [1.0; 3],
            velocity: [vx, 0.0, 0.0],
        };
        let scene = Scene {
            domain: Domain {
                min: [0.0; 3],
                max: [1.2, 1.2, 1.2],
            },
            blocks: vec![],
            balls: vec![
                ball([0.4, 0.6, 0.6], 0.12, 0.5, 0),
                ball([0.78, 0.6, 0.6], 0.08, -0.5, 1),
            ],
            ..block_scene(fluid)
        };
        let momentum = |vel: &[[f32; 4]]| {
            let mut p = [0.0f64; 3];
            let mut speed = 0.0f64;
            for v in vel {
                for k in 0..3 {
                    p[k] += v[k] as f64;
                }
                speed += (0..3).map(|k| (v[k] as f64).powi(2)).sum::<f64>().sqrt();
            }
            (p, speed)
        };
        // run_steps starts from the same particles (seed 1).
        let (p0, s0) = momentum(&scene.particles(1).vel);
        // 0.3 s: the balls meet after about 0.18 s and merge.
        let d = run_steps(&ctx, &scene, 300, Neighbors::Grid, SortAlgo::Counting);
        let n = d.vel.len();
        let (p1, _) = momentum(&d.vel);
        // The premise: they collided (the small ball's particles turned back or stopped)
        // and no particle came near a wall.
        let h = scene.fluid.h;
        for x in &d.pos {
            assert!(
                (0..3).all(|k| x[k] > h && x[k] < 1.2 - h),
                "{solver_kind:?}: a particle near a wall at {x:?}"
            );
        }
        let small_vx: f64 = (0..n)
            .filter(|&i| d.attr[i][3].to_bits() == 1)
            .map(|i| d.vel[i][0] as f64)
            .sum();
        assert!(
            small_vx > -0.25 * 0.5 * n as f64,
            "{solver_kind:?}: no collision"
        );
        let dp = (0..3).map(|k| (p1[k] - p0[k]).powi(2)).sum::<f64>().sqrt();
        // Measured (llvmpipe, 2026-11-25): WCSPH, PCISPH and DFSPH lose 1e-8..3e-8 of the
        // total speed, f32 rounding; PBF 2e-4 (1.6e-4 with vorticity on), probably where a
        // pair is one-sided: its neighbour sets come from the step's start positions while
        // its corrections act at the predicted ones (a known gap, README).
        let bound = if solver_kind == Solver::Pbf {
            1e-3
        } else {
            1e-6
        };
        assert!(
            dp < bound * s0,
            "{solver_kind:?}: momentum {p0:?} -> {p1:?} (|dp| {dp:.3e} of {s0:.3e})"
        );
    }
    common::finish(&ctx);
}
