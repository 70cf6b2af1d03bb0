//! SPH benchmarks: steps per second and per-pass ms over N and neighbour strategies, and
//! the dam-break stability run (32K particles, 10 000 steps).
use super::{counts, measure, BenchOptions, Row};
use crate::config::{Neighbors, SortAlgo};
use crate::error::{Error, Result};
use crate::gpu::{Context, FrameLoop, Guard, Labels, Profiler, RecordOnly};
use crate::primitives::neighbors::default_sort;
use crate::sph::run::{check, physics_stats, PhysicsStats};
use crate::sph::{Scene, SphSolver};
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
    base.fluid = base.fluid.with_overrides(&opts.switches.fluid_args)?;
    let mut rows = Vec::new();
    for (strategy, sort) in strategies(
        opts,
        &[
            (Neighbors::Grid, SortAlgo::Counting),
            (Neighbors::Hash, SortAlgo::Bitonic),
            (Neighbors::Morton, SortAlgo::OddEven),
        ],
    ) {
        // Guards release the solver and state on every path, an early `?` included.
        let solver = Guard::new(ctx, SphSolver::new(ctx, strategy, Some(sort))?);
        for n in counts(opts) {
            let scene = base.with_particles(n);
            let parts = scene.particles(opts.switches.common.seed);
            let mut st = Guard::new(ctx, solver.state(ctx, &scene, &parts)?);
            let actual = st.n as u64;
            let variant = format!("{}/{}", strategy.as_str(), sort.as_str());
            let detail = json!({ "scene": "dam-break", "particles": actual, "dt": st.dt, "fluid": scene.fluid });
            let row = measure(
                ctx,
                opts,
                &variant.replace('/', "-"),
                actual,
                "sph",
                detail,
                |prof, cmd| solver.record_step(ctx, cmd, prof, &mut st),
            );
            drop(st);
            let mut row = row?;
            row.variant = variant;
            row.extra = vec![("steps/s".into(), format!("{:.1}", 1000.0 / row.main.median))];
            rows.push(row);
        }
    }
    Ok(rows)
}

/// One stability checkpoint (stability.json).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    pub step: u64,
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
    pub dt: f32,
    pub simulated_seconds: f64,
    pub gpu_seconds: f64,
    pub wall_seconds: f64,
    pub checkpoints: Vec<Checkpoint>,
    pub mean_density_within_5_percent: bool,
}

/// Steps the stability run takes.
pub const STABILITY_STEPS: u64 = 10_000;

/// The dam break at its natural 32K particles for 10 000 steps: no NaN, every particle in
/// the domain, the settled pool's mean density within 5% of rho_0.
pub fn stability(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let mut scene = Scene::built_in("dam-break").expect("built-in");
    scene.fluid = scene.fluid.with_overrides(&opts.switches.fluid_args)?;
    if let Some(n) = opts.switches.common.particles {
        scene = scene.with_particles(n);
    }
    let (strategy, sort) = strategies(
        opts,
        &[
            (Neighbors::Grid, SortAlgo::Counting),
            (Neighbors::Hash, SortAlgo::Bitonic),
            (Neighbors::Morton, SortAlgo::OddEven),
        ],
    )[0];
    let solver = Guard::new(ctx, SphSolver::new(ctx, strategy, Some(sort))?);
    let parts = scene.particles(opts.switches.common.seed);
    let mut st = Guard::new(ctx, solver.state(ctx, &scene, &parts)?);
    let per_frame = 50u64;
    let mut frames = FrameLoop::new(ctx, 2)?;
    let mut checkpoints: Vec<Checkpoint> = Vec::new();
    let started = std::time::Instant::now();
    let frame_count = STABILITY_STEPS / per_frame;
    let result = (|| -> Result<()> {
        for chunk in 0..10 {
            let count = frame_count / 10;
            let mut work = RecordOnly(|prof: &mut Profiler, cmd| {
                prof.begin(ctx, cmd, "steps");
                for _ in 0..per_frame {
                    solver.record_step(ctx, cmd, &mut Labels, &mut st)?;
                }
                prof.end(ctx, cmd);
                Ok(())
            });
            frames.run(ctx, count, &mut work)?;
            let d = st.read(ctx)?;
            let s = Checkpoint {
                step: (chunk + 1) * count * per_frame,
                physics: physics_stats(&d, &scene),
            };
            eprintln!(
                "stability: step {:>6}: mean density / rho0 {:.4}, max speed {:.3} m/s, NaN {}, outside {}",
                s.step, s.physics.density_mean_over_rest, s.physics.max_speed, s.physics.nan, s.physics.outside_domain
            );
            checkpoints.push(s);
        }
        Ok(())
    })();
    let timings = std::mem::take(&mut frames.profiler.results);
    frames.destroy(ctx);
    drop(st);
    drop(solver);
    result?;
    let last = checkpoints
        .last()
        .map(|c| c.physics.clone())
        .ok_or_else(|| Error::Param("stability: no checkpoint".into()))?;
    let ratio = last.density_mean_over_rest;
    let density_ok = (ratio - 1.0).abs() <= 0.05;
    let gpu_ms: f64 = timings.iter().map(|t| t.frame_ms).sum();
    let summary = StabilitySummary {
        scene: scene.name.clone(),
        neighbors: strategy,
        sort,
        particles: last.particles,
        steps: STABILITY_STEPS,
        dt: scene.fluid.dt,
        simulated_seconds: STABILITY_STEPS as f64 * scene.fluid.dt as f64,
        gpu_seconds: gpu_ms / 1000.0,
        wall_seconds: started.elapsed().as_secs_f64(),
        checkpoints,
        mean_density_within_5_percent: density_ok,
    };
    std::fs::create_dir_all(&opts.out).map_err(|e| Error::Io {
        path: opts.out.display().to_string(),
        source: e,
    })?;
    let path = opts.out.join("stability.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&summary).map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e.into(),
        })? + "\n",
    )
    .map_err(|e| Error::Io {
        path: path.display().to_string(),
        source: e,
    })?;
    check(&last)?;
    let row = Row {
        variant: format!("stability {}/{}", strategy.as_str(), sort.as_str()),
        n: last.particles as u64,
        main: crate::report::stat(
            &timings
                .iter()
                .map(|t| t.frame_ms / per_frame as f64)
                .collect::<Vec<_>>(),
        )
        .ok_or_else(|| Error::Param("no frames".into()))?,
        passes: vec![],
        reps: timings.len() as u64,
        extra: vec![
            ("steps".into(), STABILITY_STEPS.to_string()),
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
    if !density_ok {
        eprintln!(
            "stability: the mean density ends {:.1}% from rho0 (limit 5%)",
            (ratio - 1.0) * 100.0
        );
    }
    Ok(vec![row])
}
