//! `fluidform experiment <name>|all`: one command per table and figure of the papers.
//! Each writes `<out>/<name>.csv`, `<name>.md` and `<name>.png` with the paper's numbers
//! beside ours, and its verdicts on the papers' findings into `<name>.findings.json`, from
//! which `findings.md` is rebuilt (so single experiments and `all` leave the same file).
pub mod adaptive;
pub mod compare;
pub mod fidelity;
pub mod findings;
pub mod lists;
pub mod measure;
pub mod shots;
pub mod solves;
pub mod surfaces;
pub mod surge;
pub mod sweeps;
pub mod tables;
pub mod thesis;

use crate::bench::Measurer;
use crate::config::Switches;
use crate::error::{Error, Result};
use crate::gpu::{Context, ContextOptions};
use crate::render::metaball::{FluidRenderer, MetaballSettings};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

fluidform_gpu::switch_enum!(
    /// The papers' tables and figures `fluidform experiment` reproduces, and our own studies.
    Experiment {
        Table2,
        Table3,
        Table4,
        Table5,
        Table6,
        Table7,
        Table8,
        Fig9,
        Adaptive,
        Scaling,
        Fidelity,
        Surfaces,
        Lists,
        Surge,
        Solves
    }
);

pub struct ExperimentOptions {
    /// The experiments to run, in order.
    pub experiments: Vec<Experiment>,
    /// None: `results/<device-slug>`.
    pub out: Option<PathBuf>,
    pub quick: bool,
    /// Device, validation, quiet and seed; nothing else is read.
    pub switches: Switches,
}

/// What every experiment of one invocation shares.
pub struct Env {
    pub out: PathBuf,
    pub quick: bool,
    pub switches: Switches,
    pub meta: Meta,
    /// Frame size of the rendering tables.
    pub width: u32,
    pub height: u32,
    /// The thesis's 2048 particles (512 with --quick).
    pub particles: usize,
    pub frames: u64,
    pub warmup: u64,
    /// GPU seconds a configuration may take before it gets fewer repetitions.
    pub budget_s: f64,
    scene: Option<thesis::ThesisScene>,
    /// Renderers made once per shader configuration (llvmpipe takes about a second to
    /// compile one) and shared by the cells of a table, each with buffers of its own, that
    /// are timed interleaved (shots.rs).
    shared: HashMap<String, FluidRenderer>,
    /// Timed frames by (settings, centres): a frame asked for again (the `none` rows
    /// several tables share) is measured once per invocation.
    pub(crate) timed: HashMap<String, shots::Timed>,
}

impl Env {
    /// The thesis scene, made (and framed) once per invocation.
    pub fn scene(&mut self, ctx: &Context) -> Result<&thesis::ThesisScene> {
        if self.scene.is_none() {
            let spacing = crate::sph::FluidParams::default().spacing();
            self.scene = Some(thesis::ThesisScene::new(
                ctx,
                self.particles,
                spacing,
                self.width,
                self.height,
                self.switches.common.seed,
            )?);
        }
        Ok(self.scene.as_ref().expect("made"))
    }

    /// The renderer of `s`'s shader configuration, made once and retuned to `s`.
    pub fn shared_renderer(
        &mut self,
        ctx: &Context,
        s: &MetaballSettings,
    ) -> Result<&mut FluidRenderer> {
        let key = renderer_key(s);
        if !self.shared.contains_key(&key) {
            self.shared
                .insert(key.clone(), FluidRenderer::new(ctx, s.clone())?);
        }
        let r = self.shared.get_mut(&key).expect("inserted");
        r.retune(s.clone())?;
        Ok(r)
    }

    /// The renderer `shared_renderer` made for `s`'s shader configuration.
    pub fn made_renderer(&self, s: &MetaballSettings) -> Result<&FluidRenderer> {
        self.shared
            .get(&renderer_key(s))
            .ok_or_else(|| Error::Bug("no shared renderer for these settings".into()))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for (_, mut r) in self.shared.drain() {
            r.destroy(ctx);
        }
    }

    /// The thesis scene once `scene` has made it.
    pub fn scene_ref(&self) -> Result<&thesis::ThesisScene> {
        self.scene
            .as_ref()
            .ok_or_else(|| Error::Param("the thesis scene is not made yet".into()))
    }

    /// Where per-configuration outputs (timings.csv, summary.json) of `name` go.
    pub fn runs(&self, name: Experiment) -> PathBuf {
        self.out.join("runs").join(name.as_str())
    }

    /// Options to measure `what` through the benchmarks, its outputs under `runs/<name>`.
    pub fn bench_options(&self, what: Measurer, name: Experiment) -> crate::bench::BenchOptions {
        let mut switches = self.switches.clone();
        switches.common.quiet = true;
        crate::bench::BenchOptions {
            what,
            out: self.runs(name),
            frames: self.frames,
            warmup: self.warmup,
            budget_s: self.budget_s,
            rounds: crate::bench::protocol::MIN_ROUNDS,
            warmup_s: if self.quick { 0.5 } else { 2.0 },
            drift: crate::bench::protocol::DRIFT,
            switches,
            character: None,
            vertices: None,
            velocities: Vec::new(),
            counts: Vec::new(),
            seconds: crate::bench::sph::STABILITY_SECONDS,
        }
    }
}

/// A renderer's shader configuration: the build and tile size choose passes and buffers
/// beside the defines.
fn renderer_key(s: &MetaballSettings) -> String {
    format!(
        "{:?} {:?} {} {}x{} {:?}",
        s.shader_defines(),
        s.build,
        s.tile,
        s.width,
        s.height,
        s.sky
    )
}

/// Where and when the numbers were measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Meta {
    pub device: String,
    pub device_type: String,
    pub driver: String,
    pub api: String,
    pub cpu: String,
    pub commit: String,
    pub date: String,
}

impl Meta {
    pub fn new(ctx: &Context) -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split(':').nth(1))
                    .map(|m| m.trim().to_string())
            })
            .unwrap_or_else(|| "unknown".into());
        let cores = std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1);
        Self {
            device: ctx.info.name.clone(),
            device_type: ctx.info.kind.clone(),
            driver: ctx.info.driver.clone(),
            api: ctx.info.api.clone(),
            cpu: format!("{cpu}, {cores} threads"),
            commit: env!("FLUIDFORM_COMMIT").into(),
            date: crate::bench::plot::today(),
        }
    }

    /// The block every markdown file ends with.
    pub fn markdown(&self, env: &Env) -> String {
        format!(
            "Device: {} ({}), driver {}, Vulkan {}. CPU: {}. Binary built from commit {}, {}. {}\n",
            self.device,
            self.device_type,
            self.driver,
            self.api,
            self.cpu,
            self.commit,
            self.date,
            match env.quick {
                true => "**--quick**: shrunk sizes and repetitions, for checking the command, not for quoting.",
                false => "Full run.",
            }
        )
    }
}

/// One bar over an experiment's configurations with elapsed time and ETA (plain lines when
/// stderr is not a terminal, nothing with --quiet).
pub struct Steps {
    bar: Option<ProgressBar>,
    plain: bool,
    name: String,
    total: u64,
    done: u64,
    start: Instant,
}

impl Steps {
    pub fn new(name: &str, total: u64, quiet: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let bar = (!quiet && terminal).then(|| {
            let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(
                    "{prefix} {bar:30} {pos}/{len} configurations, {elapsed} elapsed, ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b.set_prefix(name.to_string());
            b
        });
        Self {
            bar,
            plain: !quiet && !terminal,
            name: name.into(),
            total,
            done: 0,
            start: Instant::now(),
        }
    }

    pub fn start(&self, what: &str) {
        if let Some(b) = &self.bar {
            b.set_message(what.to_string());
        }
    }

    pub fn tick(&mut self) {
        self.done += 1;
        if let Some(b) = &self.bar {
            b.set_position(self.done);
        }
        if self.plain {
            let secs = self.start.elapsed().as_secs_f64();
            let eta = secs / self.done as f64 * (self.total - self.done) as f64;
            eprintln!(
                "{}: {}/{} configurations, {secs:.0} s elapsed, ETA {eta:.0} s",
                self.name, self.done, self.total
            );
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Append the findings and the device block to an experiment's markdown and write it as
/// `<out>/<name>.md`.
pub fn finish_md(
    env: &Env,
    name: Experiment,
    mut md: String,
    found: &[findings::Finding],
) -> Result<PathBuf> {
    md.push_str("\nFindings (every experiment's are in findings.md):\n\n");
    for f in found {
        md.push_str(&format!(
            "- {}: **{}**. {}\n",
            f.claim,
            f.verdict.word(),
            f.evidence
        ));
    }
    md.push('\n');
    md.push_str(&env.meta.markdown(env));
    let p = env.out.join(format!("{name}.md"));
    write(&p, &md)?;
    Ok(p)
}

pub fn io(path: &std::path::Path, e: std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        source: e,
    }
}

pub fn write(path: &std::path::Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| io(path, e))
}

/// Run the named experiment (or all); the files written.
pub fn run(opts: &ExperimentOptions) -> Result<Vec<PathBuf>> {
    if opts.experiments.is_empty() {
        return Err(Error::Param("experiment: no experiment named".into()));
    }
    let sw = &opts.switches;
    sw.all_scopes("experiment")?;
    let ctx = Context::new(&ContextOptions {
        device: sw.common.device.clone(),
        validation: sw.common.validation,
        present: None,
    })?;
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(ctx.info.slug()));
    std::fs::create_dir_all(&out).map_err(|e| io(&out, e))?;
    let q = opts.quick;
    let mut env = Env {
        out,
        quick: q,
        switches: sw.clone(),
        meta: Meta::new(&ctx),
        width: if q { 128 } else { 512 },
        height: if q { 128 } else { 512 },
        particles: if q { 512 } else { 2048 },
        frames: if q { 2 } else { 20 },
        warmup: if q { 1 } else { 3 },
        budget_s: if q { 4.0 } else { 10.0 },
        scene: None,
        shared: HashMap::new(),
        timed: HashMap::new(),
    };
    let result = run_all(&ctx, &mut env, &opts.experiments);
    env.destroy(&ctx);
    let files = result?;
    crate::run::common::check_validation(&ctx)?;
    Ok(files)
}

/// Set to a file: each experiment appends `experiment-<name>|start|end` (epoch seconds),
/// so scripts/gpu.sh can put the device's state beside each page of a one-process run.
pub const SPANS_ENV: &str = "FLUIDFORM_SPANS";

fn epoch_s() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

fn note_span(name: Experiment, started: f64) {
    if let Some(p) = std::env::var_os(SPANS_ENV) {
        use std::io::Write;
        let line = format!("experiment-{name}|{started:.3}|{:.3}\n", epoch_s());
        let f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(p);
        if let Ok(mut f) = f {
            let _ = f.write_all(line.as_bytes());
        }
    }
}

fn run_all(ctx: &Context, env: &mut Env, names: &[Experiment]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for &name in names {
        let t = Instant::now();
        let started = epoch_s();
        let (written, found) = match name {
            Experiment::Fig9 => sweeps::fig9(ctx, env)?,
            Experiment::Adaptive => adaptive::adaptive(env)?,
            Experiment::Scaling => sweeps::scaling(ctx, env)?,
            Experiment::Fidelity => fidelity::fidelity(env)?,
            Experiment::Surfaces => surfaces::surfaces(env)?,
            Experiment::Lists => lists::lists(ctx, env)?,
            Experiment::Surge => surge::surge(ctx, env)?,
            Experiment::Solves => solves::solves(ctx, env)?,
            Experiment::Table2
            | Experiment::Table3
            | Experiment::Table4
            | Experiment::Table5
            | Experiment::Table6
            | Experiment::Table7
            | Experiment::Table8 => {
                let def = tables::def(name)
                    .ok_or_else(|| Error::Bug(format!("{name} has no table definition")))?;
                measure::table(ctx, env, def)?
            }
        };
        findings::save(env, name, &found)?;
        note_span(name, started);
        files.extend(written);
        files.push(env.out.join(format!("{name}.findings.json")));
        eprintln!(
            "experiment {name}: {:.0} s, {} findings",
            t.elapsed().as_secs_f64(),
            found.len()
        );
    }
    files.push(findings::rebuild(env)?);
    Ok(files)
}
