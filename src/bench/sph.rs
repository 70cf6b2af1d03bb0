//! SPH benchmarks: steps per second and per-pass ms over N and neighbour strategies, and
//! the dam-break stability run (32K particles, 10 simulated seconds, any solver).
use super::protocol::{self, Case};
use super::{counts, BenchOptions, Row};
use crate::error::{Error, Result};
use crate::gpu::{Context, FrameLoop, Guard};
use crate::kinds::{Neighbors, SortAlgo};
use crate::primitives::neighbors::default_sort;
use crate::scene::Scene;
use crate::sph::errors::DensityErrorStats;
use crate::sph::params::FluidParams;
use crate::sph::stepper::{check, physics_stats, PhysicsStats, Stepper};
use crate::sph::SphSolver;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// --neighbors (with --sort or its default sort), else `all`.
pub fn strategies(
    opts: &BenchOptions,
    all: &[(Neighbors, SortAlgo)],
) -> Vec<(Neighbors, SortAlgo)> {
    let sw = &opts.switches;
    match sw.search.neighbors {
        Some(s) => vec![(s, sw.sorting.sort.unwrap_or(default_sort(s)))],
        None => all.to_vec(),
    }
}

/// One SPH step per frame on the dam break scaled to N particles.
pub fn steps(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let mut base = Scene::built_in("dam-break").expect("built-in");
    base.fluid = opts.switches.fluid_args.apply(&base.fluid)?;
    let combos = strategies(
        opts,
        &[
            (Neighbors::Grid, SortAlgo::Counting),
            (Neighbors::Hash, SortAlgo::Bitonic),
            (Neighbors::Morton, SortAlgo::OddEven),
        ],
    );
    // Guards release the solvers and states on every path, an early `?` included.
    let mut solvers = Guard::new(ctx, Vec::new());
    for &(strategy, sort) in &combos {
        solvers.push(SphSolver::new(ctx, strategy, Some(sort))?);
    }
    // Every state first (a state is made through its solver's `&mut`).
    let mut states = Guard::new(ctx, Vec::new());
    let mut keys = Vec::new();
    for (k, &(strategy, sort)) in combos.iter().enumerate() {
        for n in counts(opts) {
            let scene = base.with_particles(n);
            let parts = scene.particles(opts.switches.common.seed);
            states.push(solvers[k].state(ctx, &scene, &parts)?);
            keys.push((k, strategy, sort, scene.fluid));
        }
    }
    let solvers = &*solvers;
    let cases = states
        .iter_mut()
        .zip(&keys)
        .map(|(st, (k, strategy, sort, fluid))| {
            let solver = &solvers[*k];
            let actual = st.n as u64;
            let variant = format!("{}-{}", strategy.as_str(), sort.as_str());
            let detail =
                json!({ "scene": "dam-break", "particles": actual, "dt": st.dt, "fluid": fluid });
            // The case owns its state: each advances only in its own frames.
            Case::new(
                variant,
                actual,
                crate::sph::SCOPE,
                detail,
                move |prof, cmd| solver.record_step(ctx, cmd, prof, st),
            )
        })
        .collect();
    let mut rows = protocol::run(ctx, opts, cases)?;
    for row in &mut rows {
        row.variant = row.variant.replacen('-', "/", 1);
        row.extra = vec![("steps/s".into(), format!("{:.1}", 1000.0 / row.main.median))];
    }
    Ok(rows)
}

/// One stability checkpoint (stability.json).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    pub step: u64,
    /// Simulated seconds.
    pub time: f64,
    #[serde(flatten)]
    pub physics: PhysicsStats,
}

/// stability.json.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StabilitySummary {
    pub scene: String,
    pub neighbors: Neighbors,
    pub sort: SortAlgo,
    pub particles: usize,
    pub steps: u64,
    /// The fluid as run: solver, step (fixed, or CFL up to dt_max), targets.
    pub fluid: FluidParams,
    pub simulated_seconds: f64,
    pub gpu_seconds: f64,
    pub wall_seconds: f64,
    pub density_error: DensityErrorStats,
    pub checkpoints: Vec<Checkpoint>,
    pub mean_density_within_5_percent: bool,
    /// Why the run stopped early, if it went unstable.
    pub unstable: Option<String>,
    /// The build and the time it was measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<crate::bench::provenance::Provenance>,
}

/// Simulated seconds of the stability run unless --seconds.
pub const STABILITY_SECONDS: f64 = 10.0;

/// The dam break at its natural 32K particles for --seconds simulated seconds (default
/// 10) with the solver's own stable configuration (`solvers::own`): no NaN, every particle
/// in the domain, the settled pool's mean density within 5% of rho_0. Checkpoints every
/// tenth of the run.
pub fn stability(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let (scene, solver_kind) = stability_scene(opts)?;
    let (strategy, sort) = strategies(
        opts,
        &[
            (Neighbors::Grid, SortAlgo::Counting),
            (Neighbors::Hash, SortAlgo::Bitonic),
            (Neighbors::Morton, SortAlgo::OddEven),
        ],
    )[0];
    let mut solver = Guard::new(ctx, SphSolver::new(ctx, strategy, Some(sort))?);
    let parts = scene.particles(opts.switches.common.seed);
    let mut st = Guard::new(ctx, solver.state(ctx, &scene, &parts)?);
    let st_n = st.n as usize;
    let mut stepper = Guard::new(ctx, Stepper::new(ctx, &st, crate::run::common::SLOTS)?);
    let frame_time = stepper.frame_time;
    // Frames to cover the seconds, a hair under whole counting as whole (the f32 step
    // makes 2 s / 20 ms 100.0000025).
    let total = (opts.seconds / frame_time - 1e-4).ceil().max(1.0) as u64;
    let mut frames = FrameLoop::new(ctx, crate::run::common::SLOTS)?;
    let mut checkpoints: Vec<Checkpoint> = Vec::new();
    let started = std::time::Instant::now();
    let mut work = super::solvers::Play {
        solver: &solver,
        st: &mut st,
        stepper: &mut stepper,
    };
    let result = play_checkpoints(
        ctx,
        &mut frames,
        &mut work,
        (&scene, solver_kind),
        total,
        &mut checkpoints,
    );
    let timings = std::mem::take(&mut frames.profiler.results);
    frames.destroy(ctx);
    let (steps, simulated) = (stepper.steps_taken, stepper.sim_time);
    let density_error = stepper.error_stats(&st);
    drop(stepper);
    drop(st);
    drop(solver);
    let unstable = match &result {
        Err(Error::Unstable(m)) => Some(m.clone()),
        _ => None,
    };
    if unstable.is_none() {
        result?;
    }
    let last = checkpoints.last().map(|c| c.physics.clone());
    let ratio = last.as_ref().map_or(f64::NAN, |l| l.density_mean_over_rest);
    let density_ok = (ratio - 1.0).abs() <= 0.05;
    let gpu_ms: f64 = timings.iter().map(|t| t.frame_ms).sum();
    let summary = StabilitySummary {
        provenance: Some(crate::bench::provenance::measured(steps, 0)),
        scene: scene.name.clone(),
        neighbors: strategy,
        sort,
        particles: last.as_ref().map_or(st_n, |l| l.particles),
        steps,
        fluid: scene.fluid.clone(),
        simulated_seconds: simulated,
        gpu_seconds: gpu_ms / 1000.0,
        wall_seconds: started.elapsed().as_secs_f64(),
        density_error,
        checkpoints,
        mean_density_within_5_percent: density_ok,
        unstable: unstable.clone(),
    };
    let path = write_stability(&opts.out, &summary)?;
    if let Some(m) = unstable {
        return Err(Error::Unstable(format!(
            "{} after {:.2} simulated s (wrote {}): {m}",
            solver_kind.as_str(),
            simulated,
            path.display()
        )));
    }
    let last = last.ok_or_else(|| Error::Param("stability: no checkpoint".into()))?;
    check(&last)?;
    let row = stability_row(&summary, &timings, &last, solver_kind, ratio)?;
    if !density_ok {
        eprintln!(
            "stability: the mean density ends {:.1}% from rho0 (limit 5%)",
            (ratio - 1.0) * 100.0
        );
    }
    Ok(vec![row])
}

/// Play `total` frames in ten chunks, a physics checkpoint after each.
fn play_checkpoints(
    ctx: &Context,
    frames: &mut FrameLoop,
    work: &mut super::solvers::Play,
    (scene, solver_kind): (&Scene, crate::sph::Solver),
    total: u64,
    checkpoints: &mut Vec<Checkpoint>,
) -> Result<()> {
    let mut played = 0;
    for chunk in 1..=10u64 {
        let count = total * chunk / 10 - played;
        if count == 0 {
            continue;
        }
        frames.run(ctx, count, work)?;
        played += count;
        let d = work.st.read(ctx)?;
        let s = Checkpoint {
            step: work.stepper.steps_taken,
            time: work.stepper.sim_time,
            physics: physics_stats(&d, &scene.domain, scene.fluid.rest_density),
        };
        eprintln!(
            "stability {}: {:.2} s, step {:>6}: mean density / rho0 {:.4}, max speed {:.3} m/s, NaN {}, outside {}",
            solver_kind.as_str(), s.time, s.step, s.physics.density_mean_over_rest, s.physics.max_speed, s.physics.nan, s.physics.outside_domain
        );
        checkpoints.push(s);
    }
    Ok(())
}

/// The dam break with the solver's own stable setup and the switches applied.
fn stability_scene(opts: &BenchOptions) -> Result<(Scene, crate::sph::Solver)> {
    let mut scene = Scene::built_in("dam-break").expect("built-in");
    let solver_kind = opts
        .switches
        .fluid_args
        .solver
        .unwrap_or(scene.fluid.solver);
    // Frames of 20 ms: they bound a CFL step.
    scene.fluid.substeps = 50;
    scene.fluid = super::solvers::own(&scene.fluid, solver_kind);
    scene.fluid = opts.switches.fluid_args.apply(&scene.fluid)?;
    if let Some(n) = opts.switches.common.particles {
        scene = scene.with_particles(n);
    }
    if !(opts.seconds > 0.0 && opts.seconds.is_finite()) {
        return Err(Error::Param(format!(
            "--seconds must be positive, got {}",
            opts.seconds
        )));
    }
    Ok((scene, solver_kind))
}

/// stability.json in `out`.
fn write_stability(
    out: &std::path::Path,
    summary: &StabilitySummary,
) -> Result<std::path::PathBuf> {
    std::fs::create_dir_all(out).map_err(|e| Error::Io {
        path: out.display().to_string(),
        source: e,
    })?;
    let path = out.join("stability.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(summary).map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e.into(),
        })? + "\n",
    )
    .map_err(|e| Error::Io {
        path: path.display().to_string(),
        source: e,
    })?;
    Ok(path)
}

/// The bench row of a stable run: GPU ms per frame, simulated time and the checks.
fn stability_row(
    summary: &StabilitySummary,
    timings: &[crate::gpu::FrameTiming],
    last: &crate::sph::stepper::PhysicsStats,
    solver_kind: crate::sph::Solver,
    ratio: f64,
) -> Result<Row> {
    let (simulated, steps) = (summary.simulated_seconds, summary.steps);
    let density_ok = summary.mean_density_within_5_percent;
    let gpu_ms: f64 = timings.iter().map(|t| t.frame_ms).sum();
    let row = Row {
        interval: None,
        flagged: false,
        variant: format!(
            "stability {} {}/{}",
            solver_kind.as_str(),
            summary.neighbors.as_str(),
            summary.sort.as_str()
        ),
        n: last.particles as u64,
        // GPU ms per frame of 20 ms.
        main: crate::report::stat(&timings.iter().map(|t| t.frame_ms).collect::<Vec<_>>())
            .ok_or_else(|| Error::Param("no frames".into()))?,
        passes: vec![],
        reps: timings.len() as u64,
        extra: vec![
            ("simulated s".into(), format!("{simulated:.2}")),
            ("steps".into(), steps.to_string()),
            (
                "sim s per GPU s".into(),
                format!("{:.4}", simulated / (gpu_ms / 1000.0).max(1e-12)),
            ),
            (
                "mean density error %".into(),
                format!("{:.3}", summary.density_error.mean * 100.0),
            ),
            ("final mean density / rho0".into(), format!("{ratio:.4}")),
            ("NaN".into(), last.nan.to_string()),
            ("outside domain".into(), last.outside_domain.to_string()),
            (
                "within 5%".into(),
                if density_ok {
                    "yes".into()
                } else {
                    "NO".into()
                },
            ),
        ],
    };
    Ok(row)
}
