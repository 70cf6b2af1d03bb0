//! `experiment solves` (issue 59): a DFSPH step against a WCSPH step on the dam break
//! (64K particles; 4K with --quick), each solver at its own step and error target, played
//! in rounds whose order is shuffled per round (a fresh state each, its first frames
//! untimed so DFSPH's recorded iterations settle): the `sph` scope's GPU ms per step with
//! its interval over the rounds, the iterations, and what the median step recorded
//! (dispatches, barriers, empty dispatches).
use super::findings::{Finding, Verdict};
use super::{write, Env, Experiment, Steps};
use crate::bench::interval::Interval;
use crate::bench::solvers::{own, play, Outcome};
use crate::bench::Measurer;
use crate::error::{Error, Result};
use crate::gpu::{Context, Guard};
use crate::kinds::{Neighbors, SortAlgo};
use crate::scene::Scene;
use crate::sph::Solver;
use crate::sph::SphSolver;
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

pub const CLAIM: &str = "a DFSPH step at 64K at most 2x a WCSPH step";
const RATIO: f64 = 2.0;
const SOLVERS: [Solver; 2] = [Solver::Wcsph, Solver::Dfsph];

pub fn solves(ctx: &Context, env: &mut Env) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let n = if env.quick { 4096 } else { 65536 };
    let rounds = crate::bench::protocol::MIN_ROUNDS;
    let mut base = Scene::built_in("dam-break")?.with_particles(n);
    // Frames of 4 WCSPH steps (1.6 ms): a DFSPH frame takes one or two of its own.
    base.fluid.substeps = 4;
    let mut opts = env.bench_options(
        Measurer::Experiment(Experiment::Solves.as_str()),
        Experiment::Solves,
    );
    (opts.warmup, opts.frames) = (8, env.frames.clamp(2, 10));
    let mut sph = Guard::new(
        ctx,
        SphSolver::new(ctx, Neighbors::Grid, Some(SortAlgo::Counting))?,
    );
    let quiet = env.switches.common.quiet;
    let mut steps = Steps::new("solves", rounds * SOLVERS.len() as u64, quiet);
    let mut rng = rand::rngs::StdRng::seed_from_u64(env.switches.common.seed);
    let mut per: [Vec<Vec<f64>>; 2] = Default::default();
    let mut last: [Option<Outcome>; 2] = Default::default();
    for _ in 0..rounds {
        let order = match rng.random_bool(0.5) {
            true => [1, 0],
            false => [0, 1],
        };
        for k in order {
            let solver = SOLVERS[k];
            steps.start(&solver.as_str());
            let mut scene = base.clone();
            scene.fluid = own(&base.fluid, solver);
            let o = play(ctx, &mut sph, &scene, &opts, &solver.as_str())?;
            if let Some(m) = &o.unstable {
                return Err(Error::Unstable(format!("{}: {m}", solver.as_str())));
            }
            per[k].push(o.per_step_ms.clone());
            last[k] = Some(o);
            steps.tick();
        }
    }
    steps.finish();
    let seed = env.switches.common.seed;
    let est: Vec<Interval> = per
        .iter()
        .map(|r| Interval::of_rounds(r, seed))
        .collect::<Option<_>>()
        .ok_or_else(|| Error::Param("experiment solves: no timed step".into()))?;
    let outs: Vec<&Outcome> = last.iter().flatten().collect();
    let found = vec![finding(n, &est)];
    let mut csv = String::from(
        "solver,particles,step_ms,ci_lo_ms,ci_hi_ms,steps,mean_dt_ms,iterations,\
         divergence_iterations,dispatches,barriers,solver_dispatches,solver_barriers,\
         empty_dispatches,mean_error_pct\n",
    );
    let mut md = format!(
        "# A DFSPH step against a WCSPH step\n\nThe dam break at {n} particles, each solver at \
         its own step and error target; {rounds} rounds in shuffled order, each a fresh \
         state played {} frames untimed, then {} timed (frames of 1.6 ms). Commands: the \
         median step's (dispatches and barriers in all, the pressure solver's share, and \
         the dispatches that ran empty).\n\n| solver | ms per step [95%] | steps | mean dt \
         ms | iterations | divergence iterations | dispatches | barriers | solver \
         dispatches | solver barriers | empty | mean error % |\n|---|---|---|---|---|---|---|\
         ---|---|---|---|---|\n",
        opts.warmup, opts.frames
    );
    for ((solver, i), o) in SOLVERS.iter().zip(&est).zip(&outs) {
        let e = &o.errors;
        let dt = o.simulated_s / o.steps.max(1) as f64 * 1000.0;
        // The columns after the time, the same in both tables.
        let mut rest = vec![
            o.steps.to_string(),
            format!("{dt:.3}"),
            format!("{:.2}", e.iterations_mean),
            format!("{:.2}", e.divergence_iterations_mean),
        ];
        rest.extend(o.commands.median.iter().map(|c| c.to_string()));
        rest.push(format!("{:.3}", e.mean * 100.0));
        let name = solver.as_str();
        md += &format!("| {name} | {} | {} |\n", i.text(), rest.join(" | "));
        let times = format!("{:.6},{:.6},{:.6}", i.median, i.lo, i.hi);
        csv += &format!("{name},{n},{times},{}\n", rest.join(","));
    }
    let p_csv = env.out.join("solves.csv");
    write(&p_csv, &csv)?;
    let png = env.out.join("solves.png");
    let labels: Vec<String> = ["ms per step", "dispatches", "barriers", "empty dispatches"]
        .map(String::from)
        .to_vec();
    let series: Vec<(String, Vec<Option<f64>>)> = SOLVERS
        .iter()
        .zip(&est)
        .zip(&outs)
        .map(|((solver, i), o)| {
            let c = &o.commands.median;
            let v = [i.median, c[0] as f64, c[1] as f64, c[4] as f64];
            (solver.as_str(), v.map(|x| (x > 0.0).then_some(x)).to_vec())
        })
        .collect();
    let title = format!("dam break at {n}: a step");
    let sub = format!("{}, {}", env.meta.device, crate::bench::plot::today());
    crate::bench::plot::grouped_bars(&png, &title, &sub, &labels, &series, "per step")?;
    md.push_str("\n![a step's time and commands per solver](solves.png)\n");
    let p_md = super::finish_md(env, Experiment::Solves, md, &found)?;
    Ok((vec![p_csv, p_md, png], found))
}

/// DFSPH's step over WCSPH's at most RATIO beyond the intervals: confirmed where even the
/// greatest ratio they allow is within it, refuted where even the least is not.
fn finding(n: u32, est: &[Interval]) -> Finding {
    let (w, d) = (&est[0], &est[1]);
    let verdict = if d.hi / w.lo.max(1e-12) <= RATIO {
        Verdict::Confirmed
    } else if d.lo / w.hi.max(1e-12) > RATIO {
        Verdict::Refuted
    } else {
        Verdict::Inconclusive
    };
    Finding::new(
        CLAIM,
        verdict,
        format!(
            "at {n} particles: DFSPH {} against WCSPH {} ms per step, {:.2}x",
            d.text(),
            w.text(),
            d.median / w.median.max(1e-12)
        ),
    )
}
