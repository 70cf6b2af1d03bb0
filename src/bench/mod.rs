//! `fluidform bench <what>`: warm-up, timed repetitions, per-pass GPU ms in the output
//! contract (timings.csv + summary.json per configuration) and a sweep table
//! (sweep.csv + sweep.md) when several configurations run.
pub mod args;
pub mod control;
pub mod emission;
pub mod floor;
pub mod inside;
pub mod interval;
pub mod march;
pub mod particles;
pub mod plot;
pub mod primitives;
pub mod protocol;
pub mod provenance;
pub mod render;
pub mod skin;
pub mod solvers;
pub mod sph;

use crate::config::{Group, Switches};
use crate::error::{Error, Result};
use crate::gpu::{Context, ContextOptions, ScopeKey};
use crate::report::Stat;
use serde_json::Value;
use std::path::PathBuf;

fluidform_gpu::switch_enum!(
    /// The benchmarks of `fluidform bench`, one per subcommand.
    Bench {
        Scan,
        Sort,
        Neighbors,
        Sph,
        Stability,
        Solvers,
        Render,
        March,
        Skin,
        Inside,
        Control,
        Emission,
        Particles
    }
);

/// Who measures through the benchmarks' machinery: a benchmark, or an experiment, by its
/// name, which then labels the outputs (the benchmarks know no experiment).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Measurer {
    Bench(Bench),
    Experiment(String),
}

impl std::fmt::Display for Measurer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Measurer::Bench(b) => b.fmt(f),
            Measurer::Experiment(e) => f.write_str(e),
        }
    }
}

#[derive(Clone)]
pub struct BenchOptions {
    pub what: Measurer,
    pub out: PathBuf,
    /// Timed repetitions per configuration, spread over the protocol's rounds.
    pub frames: u64,
    pub warmup: u64,
    /// Interleaved rounds (at least `protocol::MIN_ROUNDS`).
    pub rounds: u64,
    /// Seconds the sentinel's warm-up may take before timing starts anyway.
    pub warmup_s: f64,
    /// A round is off when its sentinel or a steady pass is further than this fraction
    /// from its median (`protocol::DRIFT` unless `--drift` says otherwise).
    pub drift: f64,
    /// Seconds of GPU time a configuration may take; slower ones get fewer repetitions
    /// (at least 3), and the table reports how many each had.
    pub budget_s: f64,
    pub switches: Switches,
    /// bench skin: the character file (default builtin:walker); bench control: the scene
    /// (default giraffe).
    pub character: Option<String>,
    /// bench skin: vertices of the generated mesh (default 1M); bench inside: triangles of
    /// the refined, open copy (default 50K).
    pub vertices: Option<u32>,
    /// bench control: velocity-term gains to sweep (empty: --control-velocity or 0).
    pub velocities: Vec<f32>,
    /// Particle counts to sweep where --particles is unset (empty: the benchmark's own).
    pub counts: Vec<u32>,
    /// bench stability: simulated seconds to run.
    pub seconds: f64,
}

/// `config` of one benchmark configuration's summary.json.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BenchConfig {
    pub command: String,
    pub what: String,
    pub variant: String,
    pub n: u64,
    pub frames: u64,
    pub warmup: u64,
    pub switches: Switches,
    /// The benchmark's own description of the configuration (scene, sizes, settings).
    pub detail: Value,
}

/// `stats` of a benchmark configuration: none beyond the timings.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct NoStats {}

/// Default particle counts of a sweep: 8K ... 256K and 1M.
pub const SWEEP: &[u32] = &[
    8 << 10,
    16 << 10,
    32 << 10,
    64 << 10,
    128 << 10,
    256 << 10,
    1 << 20,
];

/// One measured configuration: a row of the sweep table.
#[derive(Clone)]
pub struct Row {
    pub variant: String,
    pub n: u64,
    /// The headline scope (e.g. "sort") over the timed frames.
    pub main: Stat,
    pub passes: Vec<(String, Stat)>,
    /// Timed repetitions behind the statistics.
    pub reps: u64,
    pub extra: Vec<(String, String)>,
    /// The headline's median of per-round medians, IQR and 95% interval.
    /// None for rows outside the protocol (simulation runs timed over simulated seconds).
    pub interval: Option<interval::Interval>,
    /// A round stayed off after its rerun (protocol.rs): the row is not to be trusted.
    pub flagged: bool,
}

impl Row {
    /// The headline's estimate under the protocol (None for rows outside it).
    pub fn estimate(&self) -> Option<interval::Estimate> {
        self.interval.map(|interval| interval::Estimate {
            interval,
            flagged: self.flagged,
        })
    }

    /// The statistics of timestamp scope `key`; an error where it was not recorded.
    pub fn pass(&self, key: ScopeKey) -> Result<&Stat> {
        self.passes
            .iter()
            .find(|(k, _)| k == key.path())
            .map(|(_, s)| s)
            .ok_or_else(|| key.missing(self.passes.iter().map(|(k, _)| k.as_str())))
    }
}

pub fn run(opts: &BenchOptions) -> Result<Vec<Row>> {
    if opts.frames == 0 {
        return Err(Error::Param("--frames must be at least 1".into()));
    }
    let sw = &opts.switches;
    sw.all_scopes("bench")?;
    let ctx = Context::new(&ContextOptions {
        device: sw.common.device.clone(),
        validation: sw.common.validation,
        present: None,
    })?;
    let Measurer::Bench(bench) = opts.what.clone() else {
        return Err(Error::Bug(format!(
            "bench::run runs benchmarks; {} measures through bench::measure",
            opts.what
        )));
    };
    let rows = match bench {
        Bench::Scan => {
            sw.reject_unused("bench scan", &[])?;
            primitives::scan(&ctx, opts)?
        }
        Bench::Sort => {
            sw.reject_unused("bench sort", &[Group::Sort])?;
            primitives::sort(&ctx, opts)?
        }
        Bench::Neighbors => {
            sw.reject_unused("bench neighbors", &[Group::Sort, Group::Neighbors])?;
            primitives::neighbors(&ctx, opts)?
        }
        Bench::Sph => {
            sw.reject_unused("bench sph", &[Group::Sort, Group::Neighbors, Group::Fluid])?;
            sph::steps(&ctx, opts)?
        }
        Bench::Stability => {
            sw.reject_unused(
                "bench stability",
                &[Group::Sort, Group::Neighbors, Group::Fluid],
            )?;
            sph::stability(&ctx, opts)?
        }
        Bench::Solvers => {
            sw.reject_unused(
                "bench solvers",
                &[Group::Sort, Group::Neighbors, Group::Fluid],
            )?;
            solvers::solvers(&ctx, opts)?
        }
        Bench::Render => {
            sw.reject_unused("bench render", &[Group::Metaball, Group::Camera])?;
            render::render(&ctx, opts)?
        }
        Bench::March => {
            sw.reject_unused("bench march", &[Group::Metaball, Group::Camera])?;
            march::march(&ctx, opts)?
        }
        Bench::Skin => {
            sw.reject_unused("bench skin", &[Group::Character])?;
            skin::skin(&ctx, opts)?
        }
        Bench::Inside => {
            sw.reject_unused("bench inside", &[])?;
            inside::inside(opts)?
        }
        Bench::Control => {
            sw.reject_unused(
                "bench control",
                &[Group::Control, Group::Character, Group::Fluid],
            )?;
            control::control(opts)?
        }
        Bench::Emission => {
            sw.reject_unused(
                "bench emission",
                &[Group::Sort, Group::Neighbors, Group::Fluid, Group::Emission],
            )?;
            emission::emission(&ctx, opts)?
        }
        Bench::Particles => {
            sw.reject_unused("bench particles", &[Group::Sort, Group::Particles])?;
            particles::particles(&ctx, opts)?
        }
    };
    let notes = primitives::notes(bench, &rows);
    write_sweep(&ctx, opts, &rows, &notes)?;
    crate::run::common::check_validation(&ctx)?;
    Ok(rows)
}

/// Particle counts to measure: --particles, or the default sweep.
pub fn counts(opts: &BenchOptions) -> Vec<u32> {
    counts_or(opts, SWEEP)
}

/// --particles, else the caller's counts, else the benchmark's `default`.
pub fn counts_or(opts: &BenchOptions, default: &[u32]) -> Vec<u32> {
    match opts.switches.common.particles {
        Some(n) => vec![n],
        None if !opts.counts.is_empty() => opts.counts.clone(),
        None => default.to_vec(),
    }
}

/// A CSV field, quoted where it holds a comma, a quote or a line break.
pub(crate) fn csv_field(v: &str) -> String {
    if v.contains([',', '"', '\n']) {
        format!("\"{}\"", v.replace('"', "\"\""))
    } else {
        v.to_string()
    }
}

/// The rows as CSV and as a markdown table, a column for every pass and extra any row has.
fn sweep_tables(rows: &[Row]) -> (String, String) {
    let mut pass_names: Vec<String> = Vec::new();
    let mut extra_names: Vec<String> = Vec::new();
    for r in rows {
        for (p, _) in &r.passes {
            if !pass_names.contains(p) {
                pass_names.push(p.clone());
            }
        }
        for (k, _) in &r.extra {
            if !extra_names.contains(k) {
                extra_names.push(k.clone());
            }
        }
    }
    let mut csv = String::from(
        "variant,n,reps,median_ms,min_ms,max_ms,ns_per_element,ci_lo_ms,ci_hi_ms,q1_ms,q3_ms,flagged",
    );
    let mut md =
        format!(
        "| variant | N | reps | median ms [95% interval] | IQR | ns/element |{}{}\n|---|---|---|---|---|---|{}{}\n",
        pass_names.iter().map(|p| format!(" {p} ms |")).collect::<String>(),
        extra_names.iter().map(|p| format!(" {p} |")).collect::<String>(),
        "---|".repeat(pass_names.len()),
        "---|".repeat(extra_names.len()),
    );
    for p in &pass_names {
        csv.push_str(&format!(",{p}_ms"));
    }
    for k in &extra_names {
        csv.push_str(&format!(",{k}"));
    }
    csv.push('\n');
    for r in rows {
        let per = r.main.median * 1e6 / r.n.max(1) as f64;
        let iv = r.interval.unwrap_or_default();
        csv.push_str(&format!(
            "{},{},{},{:.6},{:.6},{:.6},{:.4},{:.6},{:.6},{:.6},{:.6},{}",
            r.variant,
            r.n,
            r.reps,
            r.main.median,
            r.main.min,
            r.main.max,
            per,
            iv.lo,
            iv.hi,
            iv.q1,
            iv.q3,
            r.flagged
        ));
        let (ci, iqr) = match r.interval {
            Some(iv) => (
                format!(" [{:.3}, {:.3}]", iv.lo, iv.hi),
                format!("{:.3}-{:.3}", iv.q1, iv.q3),
            ),
            None => (String::new(), "-".into()),
        };
        md.push_str(&format!(
            "| {}{} | {} | {} | {:.3}{ci} | {iqr} | {:.2} |",
            r.variant,
            if r.flagged { " (flagged)" } else { "" },
            r.n,
            r.reps,
            r.main.median,
            per
        ));
        for p in &pass_names {
            let v = r.passes.iter().find(|(n, _)| n == p).map(|(_, s)| s.median);
            csv.push_str(&format!(
                ",{}",
                v.map(|v| format!("{v:.6}")).unwrap_or_default()
            ));
            md.push_str(&format!(
                " {} |",
                v.map(|v| format!("{v:.3}")).unwrap_or("-".into())
            ));
        }
        for k in &extra_names {
            let v = r
                .extra
                .iter()
                .find(|(n, _)| n == k)
                .map(|(_, s)| s.as_str());
            csv.push_str(&format!(",{}", csv_field(v.unwrap_or(""))));
            md.push_str(&format!(" {} |", v.unwrap_or("-")));
        }
        csv.push('\n');
        md.push('\n');
    }
    (csv, md)
}

/// The protocol and provenance in one paragraph, for every table page.
pub fn protocol_text(opts: &BenchOptions) -> String {
    let p = crate::bench::provenance::measured(opts.frames, opts.warmup);
    format!(
        "Protocol: every configuration built first; a sentinel warm-up (up to {} s); then \
         {} shuffled rounds (seed {}) sharing up to {} timed frames per configuration (at \
         least one a round; fewer where they would exceed {} s), after {} warm-up frames \
         each. A row is the \
         median of its per-round medians with a 95% bootstrap interval; a row is flagged \
         when a round's sentinel or steady pass stayed more than {:.0}% off after one rerun \
         (rounds.csv). Commit {}, {}, measured {}.",
        opts.warmup_s,
        opts.rounds.max(protocol::MIN_ROUNDS),
        opts.switches.common.seed,
        opts.frames,
        opts.budget_s,
        opts.warmup.max(1),
        opts.drift * 100.0,
        p.commit,
        p.rustc,
        p.date
    )
}

fn write_sweep(ctx: &Context, opts: &BenchOptions, rows: &[Row], notes: &[String]) -> Result<()> {
    let io = |p: &std::path::Path, e: std::io::Error| Error::Io {
        path: p.display().to_string(),
        source: e,
    };
    std::fs::create_dir_all(&opts.out).map_err(|e| io(&opts.out, e))?;
    let (csv, mut md) = sweep_tables(rows);
    md.push_str(&format!(
        "\nDevice: {} ({}, {}, Vulkan {}). {}\n\n",
        ctx.info.name,
        ctx.info.kind,
        ctx.info.driver,
        ctx.info.api,
        protocol_text(opts),
    ));
    for n in notes {
        md.push_str(&format!("- {n}\n"));
    }
    let p = opts.out.join("sweep.csv");
    std::fs::write(&p, csv).map_err(|e| io(&p, e))?;
    let p = opts.out.join("sweep.md");
    std::fs::write(&p, md).map_err(|e| io(&p, e))?;
    let title = format!("bench {}", opts.what);
    plot::sweep(
        &opts.out.join("sweep.png"),
        &title,
        &opts.what.to_string(),
        &ctx.info.name,
        rows,
    )
}
