//! The measurement protocol of every `bench` and `experiment` table (NVIDIA's nvbench and
//! criterion are the models). A device changes speed in stretches (clocks, power, other
//! tenants), so timing one configuration after another puts each in its own stretch:
//! - every case is built (pipelines, buffers) before anything is timed;
//! - a fixed sentinel dispatch warms the device until its time is stable (bounded in s);
//! - each case runs its warm-up frames, which also size its repetitions to the budget;
//! - the cases run interleaved in at least `MIN_ROUNDS` rounds of a few frames each, in
//!   an order shuffled per round from the seed; every frame also times the sentinel;
//! - a row is the median of its per-round medians, the IQR of its frames and a bootstrap
//!   95% interval (interval.rs);
//! - a round whose sentinel, or one of the case's `steady` passes (passes that do not
//!   depend on the table's variable), moved more than `DRIFT` from the run's median is
//!   flagged and run once more; a row whose rerun is still off stays flagged.
//!
//! `rounds.csv` beside the table gives the order, each round's medians and the flags.
use super::floor::{FmaBufs, FmaIo};
use super::interval::{median, Interval};
use super::{BenchConfig, BenchOptions, Row};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{
    ComputePipeline, Context, FrameTiming, Guard, Profiler, RecordOnly, ScopeKey, FRAME,
};
use crate::report::{pass_stats, stat, Report};
use crate::trace::Traced;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::time::Instant;

/// The sentinel's timestamp scope, first in every timed frame.
pub const SENTINEL: ScopeKey = ScopeKey::new("sentinel");
/// Rounds at the least; more where a case has frames to spare.
pub const MIN_ROUNDS: u64 = 5;
/// A round is off when its sentinel or a steady pass is further than this from the median
/// (the default of `bench --drift`).
pub const DRIFT: f64 = 0.10;
/// The sentinel's warm-up is stable when two batches' medians agree within this.
const SETTLED: f64 = 0.03;
/// Frames of one warm-up batch.
const BATCH: u64 = 5;
/// The test hook: `FLUIDFORM_PERTURB=label@round,...` slows the sentinel `PERTURB_TIMES`-fold in
/// those rounds of those cases (label `<variant>-<n>`), reruns included.
pub const PERTURB_ENV: &str = "FLUIDFORM_PERTURB";
/// Sentinel dispatches in a perturbed frame: tenfold, since lavapipe's sentinel alone
/// was seen to switch between two speeds 1.9x apart within one run.
const PERTURB_TIMES: u32 = 10;
/// Iterations per invocation of the sentinel (bench/fma.comp, 64 FLOPs each).
const SENTINEL_ITERS: u32 = 256;

/// What a case records into each of its frames.
pub type Record<'a> = Box<dyn FnMut(&mut Profiler, vk::CommandBuffer) -> Result<()> + 'a>;

/// One configuration of a table: what to record each frame, and how to label it.
pub struct Case<'a> {
    pub variant: String,
    pub n: u64,
    /// The headline scope (`FRAME` for the whole frame).
    pub main: ScopeKey,
    pub detail: Value,
    /// Passes (timestamp keys) that do not depend on the table's variable: a round where
    /// one moved more than `DRIFT` from its median over the rounds of every case in
    /// `group` (the case alone without one) is flagged like a sentinel drift.
    pub steady: Vec<String>,
    /// Cases whose steady passes do the same work (a table's cells that differ only in
    /// what the steady passes do not depend on).
    pub group: Option<String>,
    pub record: Record<'a>,
}

impl<'a> Case<'a> {
    pub fn new(
        variant: impl Into<String>,
        n: u64,
        main: ScopeKey,
        detail: Value,
        record: impl FnMut(&mut Profiler, vk::CommandBuffer) -> Result<()> + 'a,
    ) -> Self {
        Self {
            variant: variant.into(),
            n,
            main,
            detail,
            steady: Vec::new(),
            group: None,
            record: Box::new(record),
        }
    }

    /// `<variant>-<n>`: the directory under runs/ and the perturbation hook's name.
    pub fn label(&self) -> String {
        format!("{}-{}", self.variant, self.n)
    }
}

/// One round of one case in the output: where it ran, what it measured, whether it drifted.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Round {
    pub round: u64,
    /// Position of the case within its round's shuffled order.
    pub position: u64,
    pub frames: u64,
    pub main_ms: f64,
    pub sentinel_ms: f64,
    /// Why the round was off ("" when it was not).
    pub off: String,
    /// The round was run again; its numbers are the rerun's.
    pub rerun: bool,
}

/// `stats` of a case's summary.json: its interval and rounds.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseStats {
    pub interval: Interval,
    pub rounds: Vec<Round>,
    /// A round was still off after its rerun.
    pub flagged: bool,
    pub sentinel_median_ms: f64,
}

/// What the warm-up did, for the page.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Warmup {
    pub seconds: f64,
    pub batches: u64,
    pub stable: bool,
    pub sentinel_ms: f64,
}

/// Which frame is which: its case and round, and whether the test hook slows its sentinel.
#[derive(Clone, Copy)]
struct Slot {
    case: usize,
    round: u64,
    perturbed: bool,
}

fn perturbed() -> Vec<(String, u64)> {
    let Ok(v) = std::env::var(PERTURB_ENV) else {
        return Vec::new();
    };
    v.split(',')
        .filter_map(|s| s.rsplit_once('@'))
        .filter_map(|(l, r)| Some((l.to_string(), r.parse().ok()?)))
        .collect()
}

struct Sentinel<'c> {
    pipe: Guard<'c, ComputePipeline<FmaIo>>,
    out: Guard<'c, crate::gpu::Buffer>,
    invocations: u64,
}

impl Sentinel<'_> {
    fn record(&self, ctx: &Context, prof: &mut Profiler, cmd: vk::CommandBuffer, times: u32) {
        {
            let _scope = prof.open(ctx, cmd, SENTINEL.scope());
            for _ in 0..times {
                let bufs = FmaBufs { out: &self.out };
                self.pipe
                    .dispatch(ctx, cmd, &bufs, &SENTINEL_ITERS, self.invocations);
            }
        }
    }
}

/// Measure `cases` under the protocol: their rows in the order given, each case's outputs
/// under `out/runs/<label>/`, and `out/rounds.csv`.
pub fn run(ctx: &Context, opts: &BenchOptions, mut cases: Vec<Case>) -> Result<Vec<Row>> {
    if opts.frames == 0 {
        return Err(Error::Param("--frames must be at least 1".into()));
    }
    if cases.is_empty() {
        return Ok(Vec::new());
    }
    let cpu = ctx.info.kind.to_lowercase().contains("cpu");
    // About a millisecond on lavapipe (noise there is a few per cent), tens of microseconds on a GPU.
    let invocations = if cpu { 1 << 12 } else { 1 << 15 };

    let sentinel = Sentinel {
        pipe: Guard::new(ctx, super::floor::FMA_PASS.pipeline(ctx, &(), 64, &[])?),
        out: Guard::new(ctx, ctx.storage_buffer("sentinel out", invocations * 16)?),
        invocations,
    };
    let quiet = opts.switches.common.quiet;
    let warm = warm_up(ctx, opts, &sentinel)?;
    // Each case's warm-up frames, which also tell how long one of its frames takes.
    let w = opts.warmup.max(1);
    let slots: Vec<Slot> = (0..cases.len())
        .flat_map(|c| (0..w).map(move |_| (c, u64::MAX)))
        .map(|(case, round)| Slot {
            case,
            round,
            perturbed: false,
        })
        .collect();
    let t = play(ctx, &sentinel, &mut cases, &slots, "warm-up", quiet)?;
    let mut per_frame_s = vec![0.0f64; cases.len()];
    for (c, v) in per_frame_s.iter_mut().enumerate() {
        let ms: Vec<f64> = t
            .iter()
            .filter(|f| slots[f.frame as usize].case == c)
            .map(|f| f.frame_ms)
            .collect();
        *v = median(&ms).unwrap_or(0.0) / 1000.0;
    }
    // Rounds and frames per round, within the budget: a slow case gets one frame a round.
    let rounds = opts.rounds.max(MIN_ROUNDS);
    let per_round: Vec<u64> = per_frame_s
        .iter()
        .map(|&s| {
            let want = opts.frames.div_ceil(rounds).max(1);
            let fit = (opts.budget_s / (s.max(1e-9) * rounds as f64)) as u64;
            want.min(fit).max(1)
        })
        .collect();
    let perturb = perturbed();
    let labels: Vec<String> = cases.iter().map(|c| c.label()).collect();
    let is_perturbed =
        |c: usize, r: u64| perturb.iter().any(|(pl, pr)| *pl == labels[c] && *pr == r);
    let mut rng = rand_pcg::Pcg32::seed_from_u64(opts.switches.common.seed ^ 0x5eed_0bad);
    let mut order: Vec<Vec<usize>> = Vec::new();
    let mut slots = Vec::new();
    for r in 0..rounds {
        let mut o: Vec<usize> = (0..cases.len()).collect();
        o.shuffle(&mut rng);
        for &c in &o {
            for _ in 0..per_round[c] {
                let perturbed = is_perturbed(c, r);
                slots.push(Slot {
                    case: c,
                    round: r,
                    perturbed,
                });
            }
        }
        order.push(o);
    }
    let timed = play(ctx, &sentinel, &mut cases, &slots, "rounds", quiet)?;
    let mut frames: Vec<(Slot, FrameTiming)> = timed
        .into_iter()
        .map(|f| (slots[f.frame as usize], f))
        .collect();
    // The run's sentinel median, over every timed frame.
    let sent: Vec<f64> = frames
        .iter()
        .filter_map(|(_, f)| SENTINEL.ms_in(f).ok())
        .collect();
    let run_sentinel = median(&sent).unwrap_or(0.0);
    // Rounds that drifted run once more, shuffled; their frames replace the first ones.
    let off = drifted(&cases, &frames, rounds, run_sentinel, opts.drift);
    if !off.is_empty() {
        let mut again: Vec<(usize, u64)> = off.iter().map(|(c, r, _)| (*c, *r)).collect();
        again.shuffle(&mut rng);
        let slots: Vec<Slot> = again
            .iter()
            .flat_map(|&(c, r)| {
                let perturbed = is_perturbed(c, r);
                (0..per_round[c]).map(move |_| Slot {
                    case: c,
                    round: r,
                    perturbed,
                })
            })
            .collect();
        let redo = play(ctx, &sentinel, &mut cases, &slots, "reruns", quiet)?;
        frames.retain(|(s, _)| !again.contains(&(s.case, s.round)));
        frames.extend(redo.into_iter().map(|f| (slots[f.frame as usize], f)));
    }
    let still = drifted(&cases, &frames, rounds, run_sentinel, opts.drift);
    if let Some(path) = &opts.switches.common.trace {
        // In the order they ran, numbered so (case, frame) names one frame.
        let mut order: Vec<(usize, FrameTiming)> =
            frames.iter().map(|(s, t)| (s.case, t.clone())).collect();
        order.sort_by(|a, b| a.1.gpu_ns.total_cmp(&b.1.gpu_ns));
        for (i, (_, t)) in order.iter_mut().enumerate() {
            t.frame = i as u64;
        }
        let traced: Vec<Traced> = order
            .iter()
            .map(|(c, t)| Traced {
                label: &labels[*c],
                timing: t,
            })
            .collect();
        let cal = crate::gpu::clock::calibrate(ctx);
        crate::trace::write_trace(path, &traced, cal, &ctx.info.name)?;
    }
    let mut rows = Vec::new();
    let mut csv = String::from("round,position,variant,n,frames,main_ms,sentinel_ms,rerun,off\n");
    let seed = opts.switches.common.seed;
    for (c, case) in cases.iter().enumerate() {
        let mut mine: Vec<&(Slot, FrameTiming)> =
            frames.iter().filter(|(s, _)| s.case == c).collect();
        mine.sort_by_key(|(s, f)| (s.round, f.frame));
        let mut per_round_ms: Vec<Vec<f64>> = Vec::new();
        let mut info = Vec::new();
        for r in 0..rounds {
            let fr: Vec<&FrameTiming> = mine
                .iter()
                .filter(|(s, _)| s.round == r)
                .map(|(_, f)| f)
                .collect();
            let ms = fr
                .iter()
                .map(|f| main_ms(case.main, f))
                .collect::<Result<Vec<_>>>()?;
            let sm: Vec<f64> = fr.iter().filter_map(|f| SENTINEL.ms_in(f).ok()).collect();
            let rerun = off.iter().any(|(oc, or, _)| *oc == c && *or == r);
            let why = still
                .iter()
                .find(|(oc, or, _)| *oc == c && *or == r)
                .map(|(_, _, w)| w.clone())
                .unwrap_or_default();
            let position = order[r as usize].iter().position(|&x| x == c).unwrap_or(0);
            let round = Round {
                round: r,
                position: position as u64,
                frames: ms.len() as u64,
                main_ms: median(&ms).unwrap_or(f64::NAN),
                sentinel_ms: median(&sm).unwrap_or(f64::NAN),
                off: why,
                rerun,
            };
            csv.push_str(&format!(
                "{},{},{},{},{},{:.6},{:.6},{},{}\n",
                r,
                position,
                super::csv_field(&case.variant),
                case.n,
                round.frames,
                round.main_ms,
                round.sentinel_ms,
                rerun,
                super::csv_field(&round.off)
            ));
            info.push(round);
            per_round_ms.push(ms);
        }
        let interval = Interval::of_rounds(&per_round_ms, seed ^ c as u64)
            .ok_or_else(|| Error::Param(format!("{}: no timed frames", case.label())))?;
        let flagged = info.iter().any(|r| !r.off.is_empty());
        let mut timings: Vec<FrameTiming> = mine.iter().map(|(_, f)| f.clone()).collect();
        for (i, t) in timings.iter_mut().enumerate() {
            t.frame = i as u64;
        }
        let reps = timings.len() as u64;
        let stats = CaseStats {
            interval,
            rounds: info,
            flagged,
            sentinel_median_ms: run_sentinel,
        };
        write_case(ctx, opts, case, &timings, w, stats)?;
        let all: Vec<f64> = per_round_ms.iter().flatten().copied().collect();
        let s = stat(&all).ok_or_else(|| Error::Param("no timed frames".into()))?;
        let main = crate::report::Stat {
            median: interval.median,
            ..s
        };
        let passes = pass_stats(&timings);
        eprintln!(
            "{:<24} n = {:>9}  {} {}{} ({reps} frames in {rounds} rounds)",
            case.variant,
            case.n,
            case.main,
            interval.text(),
            if flagged { " FLAGGED" } else { "" }
        );
        rows.push(Row {
            variant: case.variant.clone(),
            n: case.n,
            main,
            passes,
            reps,
            extra: Vec::new(),
            interval: Some(interval),
            flagged,
        });
    }
    drop(cases);
    write_protocol(opts, &csv, &warm, rounds, run_sentinel)?;
    Ok(rows)
}

/// The case's headline ms in one frame.
fn main_ms(key: ScopeKey, f: &FrameTiming) -> Result<f64> {
    if key == FRAME {
        // The frame less the sentinel, which is the protocol's, not the case's.
        return Ok(f.frame_ms - SENTINEL.ms_in(f).unwrap_or(0.0));
    }
    key.ms_in(f)
}

/// (case, round, why) of every round whose sentinel or steady pass moved past `drift`:
/// the sentinel against the run's median, a steady pass against its median over every
/// round of every case in the same steady group (or of the case alone).
fn drifted(
    cases: &[Case],
    frames: &[(Slot, FrameTiming)],
    rounds: u64,
    run_sentinel: f64,
    drift: f64,
) -> Vec<(usize, u64, String)> {
    let of = |c: usize, r: Option<u64>, key: &str| -> Option<f64> {
        let v: Vec<f64> = frames
            .iter()
            .filter(|(s, _)| s.case == c && r.is_none_or(|r| s.round == r))
            .filter_map(|(_, f)| f.pass_ms(key))
            .collect();
        median(&v)
    };
    let mut out = Vec::new();
    for (c, case) in cases.iter().enumerate() {
        let group: Vec<usize> = match &case.group {
            Some(g) => (0..cases.len())
                .filter(|&k| cases[k].group.as_ref() == Some(g))
                .collect(),
            None => vec![c],
        };
        // A pass under 5% of the case's frame is left out: its timer's own jitter would
        // pass for drift.
        let frame: Vec<f64> = frames
            .iter()
            .filter(|(s, _)| s.case == c)
            .map(|(_, f)| f.frame_ms)
            .collect();
        let floor = 0.05 * median(&frame).unwrap_or(0.0);
        let steady: Vec<(&str, f64)> = case
            .steady
            .iter()
            .filter_map(|k| {
                let v: Vec<f64> = group.iter().filter_map(|&g| of(g, None, k)).collect();
                Some((k.as_str(), median(&v)?))
            })
            .filter(|(_, mid)| *mid >= floor)
            .collect();
        for r in 0..rounds {
            let mut why = Vec::new();
            let mut check = |key: &str, mid: f64| {
                if let Some(v) = of(c, Some(r), key) {
                    let d = v / mid.max(1e-12) - 1.0;
                    if d.abs() > drift {
                        why.push(format!("{key} {:+.0}%", 100.0 * d));
                    }
                }
            };
            check(SENTINEL.path(), run_sentinel);
            for &(k, mid) in &steady {
                check(k, mid);
            }
            if !why.is_empty() {
                out.push((c, r, why.join("; ")));
            }
        }
    }
    out
}

/// Sentinel-only frames in batches until two batches agree within `SETTLED`, or until
/// `opts.warmup_s` seconds have passed.
fn warm_up(ctx: &Context, opts: &BenchOptions, s: &Sentinel) -> Result<Warmup> {
    let start = Instant::now();
    let mut last: Option<f64> = None;
    let mut batches = 0;
    loop {
        let mut work = RecordOnly(|prof: &mut Profiler, cmd| {
            s.record(ctx, prof, cmd, 1);
            Ok(())
        });
        let t = crate::run::common::play(ctx, BATCH, &mut work, "sentinel", true)?;
        batches += 1;
        let v: Vec<f64> = t.iter().filter_map(|f| SENTINEL.ms_in(f).ok()).collect();
        let m = median(&v).unwrap_or(0.0);
        let stable = last.is_some_and(|l| (m / l.max(1e-12) - 1.0).abs() <= SETTLED);
        let seconds = start.elapsed().as_secs_f64();
        if stable || seconds >= opts.warmup_s {
            return Ok(Warmup {
                seconds,
                batches,
                stable,
                sentinel_ms: m,
            });
        }
        last = Some(m);
    }
}

/// Play the frames of `slots`, each the sentinel then its case; timings keyed by slot index.
fn play(
    ctx: &Context,
    sentinel: &Sentinel,
    cases: &mut [Case],
    slots: &[Slot],
    what: &str,
    quiet: bool,
) -> Result<Vec<FrameTiming>> {
    let mut next = 0usize;
    let mut work = RecordOnly(|prof: &mut Profiler, cmd| {
        let s = slots[next];
        next += 1;
        sentinel.record(ctx, prof, cmd, if s.perturbed { PERTURB_TIMES } else { 1 });
        (cases[s.case].record)(prof, cmd)
    });
    crate::run::common::play(ctx, slots.len() as u64, &mut work, what, quiet)
}

fn write_case(
    ctx: &Context,
    opts: &BenchOptions,
    case: &Case,
    timings: &[FrameTiming],
    warmup: u64,
    stats: CaseStats,
) -> Result<()> {
    let report = Report {
        device: &ctx.info,
        config: BenchConfig {
            command: "bench".into(),
            what: opts.what.to_string(),
            variant: case.variant.clone(),
            n: case.n,
            frames: timings.len() as u64,
            warmup,
            switches: opts.switches.clone(),
            detail: case.detail.clone(),
        },
        timings,
        memory: ctx.memory_bytes(),
        stats,
        validation: opts
            .switches
            .common
            .validation
            .then(|| ctx.validation_counts()),
        barriers: ctx.tracked_barriers(),
    };
    report.write(&opts.out.join("runs").join(case.label()))?;
    Ok(())
}

/// `rounds.csv` and `protocol.json` beside the table.
fn write_protocol(
    opts: &BenchOptions,
    csv: &str,
    warm: &Warmup,
    rounds: u64,
    sentinel: f64,
) -> Result<()> {
    let io = |p: &std::path::Path, e: std::io::Error| Error::Io {
        path: p.display().to_string(),
        source: e,
    };
    std::fs::create_dir_all(&opts.out).map_err(|e| io(&opts.out, e))?;
    let p = opts.out.join("rounds.csv");
    std::fs::write(&p, csv).map_err(|e| io(&p, e))?;
    let json = serde_json::json!({
        "rounds": rounds, "seed": opts.switches.common.seed, "drift": opts.drift,
        "warmup": warm, "sentinel_median_ms": sentinel,
        "provenance": crate::bench::provenance::measured(opts.frames, opts.warmup),
    });
    let p = opts.out.join("protocol.json");
    let text = serde_json::to_string_pretty(&json).unwrap_or_default();
    std::fs::write(&p, text + "\n").map_err(|e| io(&p, e))
}
