//! The incompressible solvers (pcisph, dfsph, pbf): one step against the f64 CPU reference,
//! momentum without walls, and the control force with groups, each solver (a resting
//! pool: tests/physics.rs).
mod common;
use fluidform::gpu::{Context, Labels};
use fluidform::kinds::{Neighbors, SortAlgo};
use fluidform::scene::schema::Particles;
use fluidform::sph::Solver;
use fluidform::sph::{cpu_pressure, FluidParams, SphSolver, SphState};

const SOLVERS: [Solver; 3] = [Solver::Pcisph, Solver::Dfsph, Solver::Pbf];

/// Random points in a cube around `c` (no two closer than a third of the rest spacing),
/// random velocities of up to `speed`.
fn random_particles(f: &FluidParams, n: usize, c: f32, speed: f32, seed: u64) -> Particles {
    let s = f.spacing();
    let side = s * (n as f32).cbrt();
    common::random_particles(s, n, [c - side / 2.0; 3], side, speed, seed)
}

fn fixed_iterations(solver: Solver, k: u32) -> FluidParams {
    let mut f = FluidParams {
        solver,
        dt: 2e-3,
        ..Default::default()
    };
    (f.pcisph.min_iterations, f.pcisph.max_iterations) = (k, k);
    (f.dfsph.min_iterations, f.dfsph.max_iterations) = (k, k);
    (f.pbf.min_iterations, f.pbf.max_iterations) = (k, k);
    f.pbf.iterations = if solver == Solver::Pbf { k } else { 0 };
    f
}

/// Arrange, read, step, read. The counting sort's order inside a cell is arbitrary, so the
/// step's own sort may swap particles: both reads are put back in the order of the tag each
/// particle carries in its red colour channel (its index, exact in f32).
fn one_step(
    ctx: &Context,
    solver: &SphSolver,
    st: &mut SphState,
) -> (
    Vec<[f32; 4]>,
    Vec<[f32; 4]>,
    fluidform::sph::solver::StateDump,
) {
    ctx.one_shot(|cmd| {
        solver.record_params(ctx, cmd, st);
        solver.record_arrange(ctx, cmd, &mut Labels, st)
    })
    .unwrap()
    .unwrap();
    let before = by_tag(st.read(ctx).unwrap());
    ctx.one_shot(|cmd| solver.record_step(ctx, cmd, &mut Labels, st))
        .unwrap()
        .unwrap();
    (before.pos, before.vel, by_tag(st.read(ctx).unwrap()))
}

/// Particles tagged 0..n in their red colour channel.
fn tagged(mut p: Particles) -> Particles {
    for (i, a) in p.attr.iter_mut().enumerate() {
        a[0] = i as f32;
    }
    p
}

/// The dump in tag order.
fn by_tag(d: fluidform::sph::solver::StateDump) -> fluidform::sph::solver::StateDump {
    let n = d.pos.len();
    let mut slot = vec![usize::MAX; n];
    for (i, a) in d.attr.iter().enumerate() {
        let t = a[0] as usize;
        assert!(
            t < n && slot[t] == usize::MAX,
            "particle tags lost: {t} at {i}"
        );
        slot[t] = i;
    }
    let order = |v: &Vec<[f32; 4]>| slot.iter().map(|&i| v[i]).collect::<Vec<_>>();
    fluidform::sph::solver::StateDump {
        pos: order(&d.pos),
        vel: order(&d.vel),
        attr: order(&d.attr),
        acc: order(&d.acc),
        rho_p: slot.iter().map(|&i| d.rho_p[i]).collect(),
    }
}

#[test]
fn one_step_of_each_solver_matches_the_f64_reference() {
    let ctx = common::ctx();
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, Some(SortAlgo::Counting)).unwrap();
    // (solver, particles in a corner of the domain): the walls act in every solve.
    let cases = SOLVERS.iter().flat_map(|s| [(*s, false), (*s, true)]);
    for (s, corner) in cases {
        let f = fixed_iterations(s, 3);
        let sc = common::box_scene(f.clone(), [0.4; 3], vec![]);
        // Packed tighter than rest (up to 3x in places): every solve has work to do.
        let parts = if corner {
            // Packed a little, 2 mm off three walls, moving at up to 0.5 m/s: some into
            // a wall within the step. PBF's corrections of that packing (and of a random
            // one at the rest spacing) move pairs closer by about h, past the neighbour
            // sets of the step's start (a known gap): its particles start sparser than
            // rest, half a spacing off the walls (clumps and the walls still compress).
            let sp = f.spacing();
            let (packing, off) = if s == Solver::Pbf {
                (1.2, 0.5 * sp)
            } else {
                (0.8, 0.002)
            };
            let side = packing * sp * 400f32.cbrt();
            tagged(common::random_particles(sp, 400, [off; 3], side, 0.5, 5))
        } else {
            tagged(random_particles(&f, 400, 0.2, 0.5, 7))
        };
        let mut st = solver.state(&ctx, &sc, &parts).unwrap();
        let (pos, vel, after) = one_step(&ctx, &solver, &mut st);
        st.destroy(&ctx);
        let walls = fluidform::sph::boundary::Boundary::new(&f, sc.domain.min, sc.domain.max);
        let (x, v) = cpu_pressure::step(&f, &walls, f.dt as f64, &pos, &vel, 3);
        let vmax = v
            .iter()
            .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
            .fold(0.0, f64::max);
        let (mut ex, mut ev, mut moved) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..x.len() {
            for k in 0..3 {
                ex = ex.max((after.pos[i][k] as f64 - x[i][k]).abs());
                ev = ev.max((after.vel[i][k] as f64 - v[i][k]).abs());
                moved = moved.max((x[i][k] - pos[i][k] as f64).abs());
            }
        }
        let at = if corner { " in a corner" } else { "" };
        eprintln!("{s:?}{at}: |dx| {ex:.3e} m of moves up to {moved:.3e} m; |dv| {ev:.3e} of speeds up to {vmax:.3e} m/s");
        assert!(moved > 1e-4, "{s:?}{at}: the step moved nothing");
        // f32 against f64: the corner's packing (speeds of 13 m/s after one step) lifts
        // the rounding to 2e-3 of the motion with the cubic kernel's 32 neighbours.
        let tol = if corner { 4e-3 } else { 2e-3 };
        assert!(ex <= tol * moved, "{s:?}{at}: positions off by {ex:.3e} m");
        assert!(
            ev <= tol * vmax,
            "{s:?}{at}: velocities off by {ev:.3e} m/s"
        );
    }
    solver.destroy(&ctx);
    common::finish(&ctx);
}

/// DFSPH's neighbour lists against the grid search every pass: lists long enough for every
/// particle, lists too short for most (each overflowing particle is searched in the grid
/// and counted) and none must give the same step to float noise.
#[test]
fn dfsph_neighbor_lists_match_the_grid_search() {
    let ctx = common::ctx();
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, Some(SortAlgo::Counting)).unwrap();
    let mut runs = Vec::new();
    for list in [0u32, 4, 96] {
        let mut f = fixed_iterations(Solver::Dfsph, 3);
        f.dfsph.neighbor_list = list;
        let sc = common::box_scene(f.clone(), [0.4; 3], vec![]);
        let parts = tagged(random_particles(&f, 400, 0.2, 0.5, 7));
        let mut st = solver.state(&ctx, &sc, &parts).unwrap();
        let (_, _, after) = one_step(&ctx, &solver, &mut st);
        let overflows = st.list_overflows();
        st.destroy(&ctx);
        eprintln!("list {list}: {overflows} particles overflowed");
        runs.push((list, after, overflows));
    }
    let (_, plain, _) = &runs[0];
    let vmax = plain
        .vel
        .iter()
        .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
        .fold(0.0f32, f32::max);
    for (list, d, overflows) in &runs[1..] {
        let (mut ex, mut ev) = (0.0f32, 0.0f32);
        for i in 0..d.pos.len() {
            for k in 0..3 {
                ex = ex.max((d.pos[i][k] - plain.pos[i][k]).abs());
                ev = ev.max((d.vel[i][k] - plain.vel[i][k]).abs());
            }
        }
        eprintln!("list {list}: |dx| {ex:.3e} m, |dv| {ev:.3e} m/s of speeds up to {vmax:.3e}");
        assert!(
            ex <= 1e-6 && ev <= 1e-5 * vmax,
            "list {list} differs: {ex} m, {ev} m/s"
        );
        match list {
            4 => assert!(
                *overflows > 200,
                "only {overflows} of 400 overflowed 4 entries"
            ),
            _ => assert_eq!(*overflows, 0, "a list of {list} overflowed"),
        }
    }
    solver.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn momentum_is_conserved_without_walls() {
    let ctx = common::ctx();
    let mut solver = SphSolver::new(&ctx, Neighbors::Hash, Some(SortAlgo::Bitonic)).unwrap();
    for s in SOLVERS {
        // Pair-symmetric terms only: no gravity, viscosity (its m / rho_j weights), surface
        // tension or vorticity confinement (an external force by design).
        let mut f = FluidParams {
            solver: s,
            gravity: [0.0; 3],
            viscosity: 0.0,
            surface_tension: 0.0,
            dt: 2e-3,
            ..Default::default()
        };
        f.pbf.vorticity = 0.0;
        let sc = common::box_scene(f.clone(), [1.0; 3], vec![]);
        let parts = random_particles(&f, 500, 0.5, 0.5, 11);
        let mut st = solver.state(&ctx, &sc, &parts).unwrap();
        let p0: [f64; 3] = std::array::from_fn(|k| parts.vel.iter().map(|v| v[k] as f64).sum());
        let speed: f64 = parts
            .vel
            .iter()
            .map(|v| ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) as f64).sqrt())
            .sum();
        ctx.one_shot(|cmd| {
            for _ in 0..10 {
                solver.record_step(&ctx, cmd, &mut Labels, &mut st)?;
            }
            Ok::<_, fluidform::Error>(())
        })
        .unwrap()
        .unwrap();
        let d = st.read(&ctx).unwrap();
        st.destroy(&ctx);
        let p1: [f64; 3] = std::array::from_fn(|k| d.vel.iter().map(|v| v[k] as f64).sum());
        let changed: f64 = d
            .vel
            .iter()
            .zip(&parts.vel)
            .map(|(a, b)| (0..3).map(|k| ((a[k] - b[k]) as f64).abs()).sum::<f64>())
            .sum();
        let drift = (0..3).map(|k| (p1[k] - p0[k]).abs()).fold(0.0, f64::max);
        eprintln!("{s:?}: momentum drift {drift:.3e} (sum |v| {speed:.3e}, velocity change {changed:.3e})");
        assert!(
            changed > 0.1 * speed,
            "{s:?}: the pressure solve did nothing"
        );
        // The exchanged momentum is summed pair by pair in f32 in different orders.
        assert!(
            drift <= 1e-3 * changed,
            "{s:?}: momentum drifted by {drift:.3e}"
        );
    }
    solver.destroy(&ctx);
    common::finish(&ctx);
}

/// DFSPH iterated to convergence (a mean error of 1e-5 per solve) beside Bender &
/// Koschier's algorithm as written in sph::paper_dfsph (masses and own densities,
/// kappa / rho, the paper's factor, its stiffness only ever growing): the step removes at
/// least 85% of the compression it starts with, by the f64 densities at its positions
/// (measured: 86% of 9.5% for the random points, 91% of 2.5% for the lattice; what is
/// left is the linear prediction's second-order miss; f64 reference: the same at 40
/// iterations as at 150). The paper's leaves less (0.35% and 0.01%) by overshooting into
/// expansion, which it cannot take back, so the two steps' velocities differ (by up to
/// 10 m/s of 14 for the random points) and are printed, not compared. Random points at 1.15
/// spacings moving at up to 0.3 m/s, and a lattice at 0.97 spacings resting on a plane
/// collider (its boundary in the densities and solves). Where the solves overshoot (a
/// random packing at the rest spacing, at 0.5 m/s), a particle a solve left under-dense
/// keeps its correction and the converged step depends on the path: 3% apart there.
#[test]
fn dfsph_converges_to_the_papers_step() {
    let ctx = common::ctx();
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, Some(SortAlgo::Counting)).unwrap();
    let tol = 1e-5f32;
    let mut f = fixed_iterations(Solver::Dfsph, 2);
    f.dfsph.max_iterations = 300;
    (f.dfsph.density_error, f.dfsph.divergence_error) = (tol, tol);
    let s = f.spacing();
    let floor = 0.1f32;
    const PACK: f32 = 0.97;
    let lattice = {
        let mut pos = Vec::new();
        for (a, b, c) in
            (0..6).flat_map(|a| (0..4).flat_map(move |b| (0..6).map(move |c| (a, b, c))))
        {
            let q = |k: i32| PACK * s * k as f32;
            pos.push([0.15 + q(a), floor + 0.6 * s + q(b), 0.15 + q(c), 0.0]);
        }
        Particles {
            vel: vec![[0.0; 4]; pos.len()],
            attr: vec![[0.0, 0.0, 0.0, f32::from_bits(0)]; pos.len()],
            pos,
        }
    };
    // Random points at 1.15 spacings (clumps still compress), moving at up to 0.3 m/s.
    let side = 1.15 * s * 400f32.cbrt();
    let sparse = common::random_particles(s, 400, [0.2 - side / 2.0; 3], side, 0.3, 7);
    let mut bad = Vec::new();
    for (what, parts, plane) in [
        ("random", sparse, false),
        ("lattice on a plane", lattice, true),
    ] {
        let mut sc = common::box_scene(f.clone(), [0.4; 3], vec![]);
        if plane {
            sc.colliders = vec![fluidform::sph::Collider::Plane {
                normal: [0.0, 1.0, 0.0],
                offset: floor,
                velocity: [0.0; 3],
            }];
        }
        let mut st = solver.state(&ctx, &sc, &tagged(parts)).unwrap();
        let (pos, vel, after) = one_step(&ctx, &solver, &mut st);
        st.destroy(&ctx);
        let b = fluidform::sph::boundary::Boundary::new(&f, sc.domain.min, sc.domain.max)
            .with_colliders(&sc.colliders)
            .unwrap();
        let r = fluidform::sph::paper_dfsph::step(&f, &b, f.dt as f64, &pos, &vel, tol as f64);
        // The largest componentwise difference of GPU values `a` and reference values `b`.
        let most = |a: &[[f32; 4]], b: &[[f64; 3]]| {
            a.iter()
                .zip(b)
                .flat_map(|(p, q)| (0..3).map(move |k| (p[k] as f64 - q[k]).abs()))
                .fold(0.0f64, f64::max)
        };
        // The compression each step leaves, by the f64 densities at its positions.
        let err = |x: &[[f32; 4]]| {
            let d = fluidform::sph::cpu::evaluate(&f, &b, x, &vel).density;
            d.iter()
                .map(|r| (r / f.rest_density as f64 - 1.0).max(0.0))
                .sum::<f64>()
                / d.len() as f64
        };
        let f4 = |v: &[[f64; 3]]| -> Vec<[f32; 4]> {
            v.iter()
                .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32, 0.0])
                .collect()
        };
        let (ours, paper) = (err(&after.pos), err(&f4(&r.pos)));
        let (dv, before) = (most(&vel, &r.vel), err(&pos));
        eprintln!(
            "{what}: paper's iterations {:?}, velocity changes up to {dv:.3e} m/s; mean compression after the step {ours:.3e}, the paper's {paper:.3e}, before {before:.3e}",
            r.iterations,
        );
        bad.push((what, dv, ours, before));
    }
    for (what, dv, ours, before) in bad {
        assert!(dv > 1e-3, "{what}: the solves changed nothing");
        assert!(
            ours <= 0.15 * before,
            "{what}: our step leaves {ours:.3e} of the {before:.3e} compression"
        );
    }
    solver.destroy(&ctx);
    common::finish(&ctx);
}

/// GPU step against a paper reference: the largest componentwise difference of positions
/// and velocities, and of the reference's own velocity change (what the pressure did).
fn differences(
    (vel, after): (&[[f32; 4]], &fluidform::sph::solver::StateDump),
    (x, v): (&[[f64; 3]], &[[f64; 3]]),
    free_fall: [f64; 3],
) -> (f64, f64, f64) {
    let (mut ex, mut ev, mut dv) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..x.len() {
        for k in 0..3 {
            ex = ex.max((after.pos[i][k] as f64 - x[i][k]).abs());
            ev = ev.max((after.vel[i][k] as f64 - v[i][k]).abs());
            dv = dv.max((v[i][k] - vel[i][k] as f64 - free_fall[k]).abs());
        }
    }
    (ex, ev, dv)
}

/// 7 x 7 x 7 particles at 0.99 rest spacings around (0.2, 0.2, 0.2), each moved by up to
/// 0.02 spacings, moving at up to `speed`: compressed everywhere but at the surface, with
/// corrections far below a spacing.
fn jittered_lattice(s: f32, speed: f32, seed: u64) -> Particles {
    let mut rng = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((rng >> 33) as f32 / (1u64 << 31) as f32) * 2.0 - 1.0
    };
    let (mut pos, mut vel) = (Vec::new(), Vec::new());
    for k in 0..7 * 7 * 7 {
        let q = |c: i32| 0.2 + 0.99 * s * (c - 3) as f32;
        let c = [q(k % 7), q(k / 7 % 7), q(k / 49)];
        pos.push([
            c[0] + 0.02 * s * next(),
            c[1] + 0.02 * s * next(),
            c[2] + 0.02 * s * next(),
            0.0,
        ]);
        vel.push([speed * next(), speed * next(), speed * next(), 0.0]);
    }
    Particles {
        attr: vec![[0.0, 0.0, 0.0, f32::from_bits(0)]; pos.len()],
        pos,
        vel,
    }
}

/// PCISPH and PBF against sph::paper_pcisph and sph::paper_pbf (Solenthaler & Pajarola
/// 2009 and Macklin & Mueller 2013 as the papers write them, not the shaders' formulas):
/// a jittered lattice at 0.99 spacings moving at up to 0.3 m/s, away from the walls, with
/// gravity the only other force (at 0.95 spacings, 5% mean compression, the paper's PCISPH
/// iterations wander at 7% error, its delta halved too). PCISPH converged (to 1e-6): whatever the
/// iteration details (the GPU's own per-particle delta, relaxed by half, against the
/// paper's prototype), both reach the same step. PBF after 4 iterations: the paper's
/// Jacobi rounds are fixed, so the GPU must take the same path. The GPU searches its grid
/// from the moving positions every iteration, the paper keeps the prediction's neighbours:
/// the reference does both (here they agree; at 0.95 spacings the paper's lists were 0.7%
/// off, a search every iteration 1e-5). No s_corr, XSPH or vorticity (not compared).
#[test]
fn pcisph_and_pbf_match_the_papers_steps() {
    let ctx = common::ctx();
    let mut solver = SphSolver::new(&ctx, Neighbors::Grid, Some(SortAlgo::Counting)).unwrap();
    let tol = 1e-6f32;
    let mut bad = Vec::new();
    for s in [Solver::Pcisph, Solver::Pbf] {
        let mut f = fixed_iterations(s, 4);
        (f.viscosity, f.surface_tension) = (0.0, 0.0);
        (f.pbf.scorr_k, f.pbf.xsph, f.pbf.vorticity) = (0.0, 0.0, 0.0);
        if s == Solver::Pcisph {
            (f.pcisph.min_iterations, f.pcisph.max_iterations) = (3, 500);
            f.pcisph.density_error = tol;
        }
        let parts = jittered_lattice(f.spacing(), 0.3, 7);
        let sc = common::box_scene(f.clone(), [0.4; 3], vec![]);
        let mut st = solver.state(&ctx, &sc, &tagged(parts)).unwrap();
        let (pos, vel, after) = one_step(&ctx, &solver, &mut st);
        st.destroy(&ctx);
        let (dt, g) = (f.dt as f64, f.gravity.map(|c| c as f64));
        let (x, v, what) = match s {
            Solver::Pcisph => {
                let paper = |omega| {
                    fluidform::sph::paper_pcisph::step(&f, dt, g, &pos, &vel, tol as f64, omega)
                };
                let (x1, v1, it1) = paper(1.0);
                let (ex, ev, _) = differences((&vel, &after), (&x1, &v1), g.map(|c| c * dt));
                eprintln!("Pcisph, the paper's delta: {it1} iterations, |dx| {ex:.3e} m, |dv| {ev:.3e} m/s");
                let (x, v, it) = paper(0.5);
                (x, v, format!("the paper's delta halved: {it} iterations"))
            }
            _ => {
                let paper = fluidform::sph::paper_pbf::step(&f, dt, g, &pos, &vel, 4, false);
                let (ex, ev, _) =
                    differences((&vel, &after), (&paper.0, &paper.1), g.map(|c| c * dt));
                eprintln!("Pbf, the paper's neighbours (once, at the prediction): |dx| {ex:.3e} m, |dv| {ev:.3e} m/s");
                let (x, v) = fluidform::sph::paper_pbf::step(&f, dt, g, &pos, &vel, 4, true);
                (
                    x,
                    v,
                    "4 iterations, neighbours found every iteration".to_string(),
                )
            }
        };
        let (ex, ev, dv) = differences((&vel, &after), (&x, &v), g.map(|c| c * dt));
        eprintln!(
            "{s:?} ({what}): |dx| {ex:.3e} m, |dv| {ev:.3e} m/s of pressure velocity changes up to {dv:.3e} m/s"
        );
        // Measured: PCISPH 5.6e-4 of the velocity change (it shrinks with tol: 3e-3 at
        // 1e-5), PBF 8e-5 (float noise; with the paper's neighbours 8e-5 too here).
        let rel = if s == Solver::Pcisph { 2e-3 } else { 1e-3 };
        bad.push((s, dv, ev, ex, dt, rel));
    }
    for (s, dv, ev, ex, dt, rel) in bad {
        assert!(dv > 1e-2, "{s:?}: the solves changed nothing");
        assert!(ev <= rel * dv, "{s:?}: velocities off by {ev:.3e} m/s");
        assert!(ex <= rel * dv * dt, "{s:?}: positions off by {ex:.3e} m");
    }
    solver.destroy(&ctx);
    common::finish(&ctx);
}
