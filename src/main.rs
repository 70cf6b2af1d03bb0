//! The command line: devices | run | bench | plot | inspect | experiment.
use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use fluidform::config::Switches;
use fluidform::run::{run, RunOptions, DEFAULT_SCENE};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "fluidform",
    version = concat!(
        env!("CARGO_PKG_VERSION"),
        ", commit ",
        env!("FLUIDFORM_COMMIT"),
        ", ",
        env!("FLUIDFORM_RUSTC")
    ),
    about = "Rust + Vulkan testbed for liquid characters",
    after_help = overview()
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// List Vulkan devices and whether each has every feature fluidform needs
    Devices {
        /// Print JSON instead of text
        #[arg(long)]
        json: bool,
        /// Print only the results/ folder name of the device `run` would pick
        #[arg(long)]
        slug: bool,
        /// With --slug: the device to name (index or name substring)
        #[arg(long)]
        device: Option<String>,
    },
    /// Play a scene and write frames, timings.csv and summary.json
    Run {
        /// A built-in scene (`fluidform scene list`) or a TOML scene file
        #[arg(long, default_value = DEFAULT_SCENE)]
        scene: String,
        /// Frames to play (default: the scene's own count)
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
        frames: Option<u64>,
        #[arg(long, default_value = "out/run")]
        out: PathBuf,
        /// Save every k-th frame as frame_NNNN.png (0: none)
        #[arg(long, default_value_t = 1)]
        save_every: u64,
        #[command(flatten)]
        switches: Switches,
    },
    /// Open a scene in a window: camera, live switches, GPU timings, timeline (keys
    /// below; without a display, run headless with `run`)
    #[command(after_help = fluidform::window::command::keys_help())]
    View(fluidform::window::WindowArgs),
    /// Benchmark an algorithm. Without --particles it sweeps N = 8K..1M (scan adds 16M).
    Bench {
        #[command(subcommand)]
        what: fluidform::bench::args::BenchWhat,
        #[arg(long, global = true, default_value = "out/bench")]
        out: PathBuf,
        /// Timed repetitions per configuration
        #[arg(long, global = true, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
        frames: u64,
        /// Untimed warm-up repetitions
        #[arg(long, global = true, default_value_t = 5)]
        warmup: u64,
        /// Seconds one configuration may take; slower ones get fewer repetitions (one
        /// frame a round at the least)
        #[arg(long, global = true, default_value_t = 300.0)]
        budget_s: f64,
        /// Interleaved rounds the timed frames are spread over (at least 5)
        #[arg(long, global = true, default_value_t = 5, value_parser = clap::value_parser!(u64).range(5..=1000))]
        rounds: u64,
        /// Seconds the sentinel's warm-up may take before timing starts anyway
        #[arg(long, global = true, default_value_t = 2.0)]
        warmup_s: f64,
        /// Percent a round's sentinel or steady pass may move from its median before the
        /// round is rerun and, if still off, its row flagged (raise it on a shared machine)
        #[arg(long, global = true, default_value_t = 100.0 * fluidform::bench::protocol::DRIFT)]
        drift: f64,
    },
    /// Plot a sweep.csv (e.g. a committed results/<device>/sph.csv) as a PNG
    Plot {
        /// The sweep CSV (variant,n,reps,median_ms,min_ms,max_ms,...)
        csv: PathBuf,
        /// The PNG to write
        #[arg(long)]
        out: PathBuf,
        /// Title, e.g. "bench sph"
        #[arg(long)]
        title: String,
        /// What the median times (axis label), e.g. "sph step"
        #[arg(long)]
        scope: String,
        /// The device the CSV was measured on
        #[arg(long)]
        device: String,
        /// The date it was measured (YYYY-MM-DD)
        #[arg(long)]
        date: String,
    },
    /// The built-in scenes: list them, or print one's TOML to copy and edit
    Scene {
        #[command(subcommand)]
        what: SceneWhat,
    },
    /// What a character or mesh file (.glb, .gltf, .obj, builtin:walker, builtin:giraffe)
    /// holds: triangles, vertices, joints, animations, bounds, closedness, volume, warnings
    Inspect {
        file: String,
        /// Print JSON instead of text
        #[arg(long)]
        json: bool,
        /// The file's up axis: y (default), -y, z, -z, x, -x
        #[arg(long)]
        up: Option<fluidform::character::anim::Up>,
        /// Draw the rest pose from the front and the side, with its skeleton, into this PNG
        #[arg(long)]
        picture: Option<PathBuf>,
    },
    /// Reproduce a table or figure of the papers, or run one of our studies; writes
    /// <out>/<name>.csv, .md, .png and findings.md. `all` runs every one in order, `list`
    /// prints their names
    Experiment {
        #[arg(value_parser = ExperimentName)]
        name: String,
        /// Output directory (default results/<device-slug>)
        #[arg(long)]
        out: Option<PathBuf>,
        /// Shrunk sizes and repetitions: `all` in a few minutes on lavapipe
        #[arg(long)]
        quick: bool,
        #[command(flatten)]
        common: fluidform::config::CommonArgs,
    },
    /// Every device's results side by side: each table's numbers per device beside the
    /// paper's, and each finding's verdict per device; writes <results>/devices.md
    Compare {
        /// The folder with one results folder per device
        #[arg(long, default_value = "results")]
        results: PathBuf,
    },
}

#[derive(Subcommand)]
enum SceneWhat {
    /// Every built-in scene: name, kind and what it shows
    List,
    /// Print a built-in scene's TOML (`fluidform scene show demo > my.toml`, edit, then
    /// `fluidform run --scene my.toml`)
    Show { name: String },
}

/// Errors print as one line: the error and any cause its message does not already hold.
fn main() -> std::process::ExitCode {
    fluidform::bench::provenance::init();
    match real_main() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let mut msg = e.to_string();
            for cause in e.chain().skip(1) {
                let c = cause.to_string();
                if !msg.contains(&c) {
                    msg = format!("{msg}: {c}");
                }
            }
            eprintln!("error: {}", msg.replace('\n', " "));
            std::process::ExitCode::FAILURE
        }
    }
}

/// One arm per command (long because it is the dispatch table; each arm is short).
fn real_main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command.unwrap_or(Command::Run {
        scene: DEFAULT_SCENE.into(),
        frames: None,
        out: "out/run".into(),
        save_every: 1,
        switches: Switches::parse_default(),
    }) {
        Command::Devices { json, slug, device } => {
            if slug {
                let ctx = fluidform::gpu::Context::new(&fluidform::gpu::ContextOptions {
                    device,
                    validation: false,
                    present: None,
                })?;
                println!("{}", ctx.info.slug());
                return Ok(());
            }
            Ok(fluidform::gpu::device::print_devices(json)?)
        }
        Command::Run {
            scene,
            frames,
            out,
            save_every,
            switches,
        } => run_command(RunOptions {
            scene,
            frames,
            out,
            save_every,
            switches,
        }),
        Command::View(args) => Ok(fluidform::window::view(args.into())?),
        Command::Bench {
            what,
            out,
            frames,
            warmup,
            budget_s,
            rounds,
            warmup_s,
            drift,
        } => {
            let timing = fluidform::bench::args::Timing {
                frames,
                warmup,
                budget_s,
                rounds,
                warmup_s,
                drift,
            };
            let (out, rows) = fluidform::bench::args::run(what, out, timing)?;
            print!("{}", std::fs::read_to_string(out.join("sweep.md"))?);
            eprintln!("{rows} configurations; wrote {}", out.display());
            Ok(())
        }
        Command::Plot {
            csv,
            out,
            title,
            scope,
            device,
            date,
        } => {
            let rows = fluidform::bench::plot::read_sweep(&csv)?;
            fluidform::bench::plot::sweep_dated(&out, &title, &scope, &device, &date, &rows)?;
            println!("wrote {}", out.display());
            Ok(())
        }
        Command::Scene { what } => {
            use fluidform::scene::builtin;
            match what {
                SceneWhat::List => print!("{}", builtin::listing()),
                SceneWhat::Show { name } => print!("{}", builtin::shown(&name)?),
            }
            Ok(())
        }
        Command::Inspect {
            file,
            json,
            up,
            picture,
        } => {
            use fluidform::inspect::inspect;
            print!("{}", inspect(&file, up, picture.as_deref(), json)?);
            Ok(())
        }
        Command::Experiment {
            name,
            out,
            quick,
            common,
        } => {
            use fluidform::experiment::Experiment;
            let experiments = match name.as_str() {
                "list" => {
                    Experiment::all().iter().for_each(|e| println!("{e}"));
                    return Ok(());
                }
                "all" => Experiment::all().to_vec(),
                some => some
                    .split(',')
                    .map(|one| one.parse::<Experiment>().map_err(anyhow::Error::msg))
                    .collect::<Result<Vec<_>, _>>()?,
            };
            if common.trace.is_some() {
                bail!("experiment: --trace is for run and bench (an experiment measures many tables; trace one configuration with bench)");
            }
            if common.particles.is_some() {
                bail!("experiment: --particles is not used (each experiment sets its own counts)");
            }
            let mut switches = Switches::parse_default();
            switches.common = common;
            let files = fluidform::experiment::run(&fluidform::experiment::ExperimentOptions {
                experiments,
                out,
                quick,
                switches,
            })?;
            for f in &files {
                println!("wrote {}", f.display());
            }
            Ok(())
        }
        Command::Compare { results } => {
            let p = fluidform::experiment::compare::write_devices(&results)?;
            println!("wrote {}", p.display());
            Ok(())
        }
    }
}

/// `run`: play the scene, print its summary and where the files went.
fn run_command(opts: RunOptions) -> Result<()> {
    let out = opts.out.clone();
    let r = run(&opts)?;
    fluidform::run::print_summary(&r.summary);
    // One closing line: where the files went.
    let anim = r
        .animation
        .as_ref()
        .map(|p| format!(", {}", p.display()))
        .unwrap_or_default();
    let exports = match r.exports.len() {
        0 => String::new(),
        k => format!(", {k} particle files and particles.csv"),
    };
    use fluidform::run::RunStats::Sph;
    let control = matches!(&r.summary.stats, Sph(s) if s.control.is_some());
    let control = if control { ", control.csv" } else { "" };
    println!(
        "wrote {} frame PNGs{anim}{exports}{control}, timings.csv and summary.json to {}",
        r.pngs.len(),
        out.display()
    );
    Ok(())
}

/// The top-level help's closing lines: what `bench` and `experiment` take.
fn overview() -> String {
    let names = |v: Vec<String>| v.join(", ");
    format!(
        "Without a command, fluidform runs the built-in liquid character (`run`).\n\
         Benchmarks (fluidform bench NAME --help): {}\n\
         Experiments (fluidform experiment NAME): {}, all, list\n\
         Built-in scenes: fluidform scene list. Documentation: README.md and docs/.",
        names(
            fluidform::bench::Bench::all()
                .iter()
                .map(|b| b.as_str())
                .collect()
        ),
        names(
            fluidform::experiment::Experiment::all()
                .iter()
                .map(|e| e.as_str())
                .collect()
        ),
    )
}

/// `experiment`'s names: every experiment, `all` and `list`, each shown in --help; any
/// other is refused naming them.
#[derive(Clone)]
struct ExperimentName;

impl ExperimentName {
    fn names() -> Vec<clap::builder::PossibleValue> {
        use clap::builder::PossibleValue;
        let mut v: Vec<PossibleValue> = fluidform::experiment::Experiment::all()
            .iter()
            .map(|e| PossibleValue::new(e.as_str()))
            .collect();
        v.push(PossibleValue::new("all").help("every experiment, in this order"));
        v.push(PossibleValue::new("list").help("print the names"));
        v
    }
}

impl clap::builder::TypedValueParser for ExperimentName {
    type Value = String;

    fn parse_ref(
        &self,
        _cmd: &clap::Command,
        _arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        let v = value.to_string_lossy().to_string();
        let names = Self::names();
        // One name, or several joined by commas (run in one process, sharing pipelines).
        let parts: Vec<&str> = v.split(',').collect();
        let bad = parts.iter().find(|p| {
            !names.iter().any(|n| n.matches(p, false))
                || (parts.len() > 1 && (**p == "all" || **p == "list"))
        });
        let Some(bad) = bad else {
            return Ok(v);
        };
        let all: Vec<&str> = names.iter().map(|n| n.get_name()).collect();
        Err(clap::Error::raw(
            clap::error::ErrorKind::InvalidValue,
            format!(
                "unknown experiment '{bad}' (one of: {}, or several joined by commas)\n",
                all.join(", ")
            ),
        ))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue>>> {
        Some(Box::new(Self::names().into_iter()))
    }
}

trait ParseDefault {
    fn parse_default() -> Self;
}

impl ParseDefault for Switches {
    fn parse_default() -> Self {
        #[derive(Parser)]
        struct Only {
            #[command(flatten)]
            s: Switches,
        }
        Only::parse_from(["fluidform"]).s
    }
}
