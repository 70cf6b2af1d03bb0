//! The command line: devices | run | bench | plot | inspect | experiment.
use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use fluidform::config::{
    CameraArgs, CharacterArgs, CommonArgs, FluidArgs, FrameArgs, MetaballArgs, NeighborArgs,
    SortArgs, Switches,
};
use fluidform::run::{run, RunOptions, DEFAULT_SCENE};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "fluidform",
    version,
    about = "Rust + Vulkan testbed for liquid characters"
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
        what: BenchWhat,
        #[arg(long, global = true, default_value = "out/bench")]
        out: PathBuf,
        /// Timed repetitions per configuration
        #[arg(long, global = true, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
        frames: u64,
        /// Untimed warm-up repetitions
        #[arg(long, global = true, default_value_t = 5)]
        warmup: u64,
        /// Seconds one configuration may take; slower ones get fewer repetitions (>= 3)
        #[arg(long, global = true, default_value_t = 300.0)]
        budget_s: f64,
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
    /// Reproduce a table or figure of the papers: table2..table8, fig9, adaptive,
    /// scaling, fidelity, surfaces, or all (list: their names); writes <out>/<name>.csv,
    /// .md, .png and findings.md
    Experiment {
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

/// The benchmarks, each with only the switches it uses.
#[derive(Subcommand)]
enum BenchWhat {
    /// Exclusive scan of u32, beside a copy of the same bytes
    Scan {
        #[command(flatten)]
        common: CommonArgs,
    },
    /// Key/value sorts: odd-even merge, bitonic, counting (or --sort)
    Sort {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        sorting: SortArgs,
    },
    /// Fixed-radius neighbour search per strategy (or --neighbors, --sort)
    Neighbors {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        sorting: SortArgs,
        #[command(flatten)]
        search: NeighborArgs,
    },
    /// One SPH step of the dam break scaled to N, per neighbour strategy
    Sph(SphBench),
    /// The 32K dam break for 10 simulated seconds (or --seconds) with the solver's own
    /// stable step (or --solver), with physics checkpoints
    Stability {
        #[command(flatten)]
        sph: SphBench,
        /// Simulated seconds
        #[arg(long, default_value_t = fluidform::bench::sph::STABILITY_SECONDS)]
        seconds: f64,
    },
    /// The dam break per pressure solver (or --solver) at 16K, 64K, 256K (or --particles):
    /// each at its own stable step and at mean density error <= 1% and <= 0.1%; times
    /// --frames frames of 20 ms after --warmup frames
    Solvers(SphBench),
    /// GPU skinning per method (or --skinning) on a character and on a generated mesh
    Skin {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        character: CharacterArgs,
        /// Character file (.glb, .gltf, .obj) or builtin:walker (the default)
        #[arg(long = "character", value_name = "FILE")]
        file: Option<String>,
        /// Vertices of the generated mesh (copies of the walker; default 1048576)
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=(1 << 26)))]
        vertices: Option<u32>,
    },
    /// How fast a control target fills per --adaptive mode (all three when unset): the
    /// built-in giraffe (or --scene) for --frames frames (the cap); time to 90% coverage
    Control {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        control: fluidform::config::ControlArgs,
        #[command(flatten)]
        character: CharacterArgs,
        #[command(flatten)]
        fluid_args: FluidArgs,
        /// Scene with a [control] target (built-in name or TOML file; default giraffe)
        #[arg(long)]
        scene: Option<String>,
        /// Velocity-term gains K to sweep beside the adaptive modes (default: 0, or
        /// --control-velocity)
        #[arg(long, value_delimiter = ',', value_name = "K,...")]
        velocities: Vec<f32>,
    },
    /// Seed 002's figure 9: frames per second of an emitting scene at 8K..64K particles
    /// (or --particles), counting grid and hash + bitonic (or --neighbors, --sort)
    Emission {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        sorting: SortArgs,
        #[command(flatten)]
        search: NeighborArgs,
        #[command(flatten)]
        fluid_args: FluidArgs,
        #[command(flatten)]
        emission: fluidform::config::EmissionArgs,
    },
    /// Particle systems (seed 003): update, sort and draw ms at 64K, 256K and 1M sprites
    /// (or --particles), per integrator and sort (or --integrator, --sort)
    Particles {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        frame: FrameArgs,
        #[command(flatten)]
        sorting: SortArgs,
        #[command(flatten)]
        particle: fluidform::config::ParticleArgs,
    },
    /// The metaball renderer on a resting blob, per list (or --list)
    Render {
        #[command(flatten)]
        common: CommonArgs,
        #[command(flatten)]
        frame: FrameArgs,
        #[command(flatten)]
        metaball: MetaballArgs,
        #[command(flatten)]
        camera: CameraArgs,
    },
}

/// The switches of the SPH benchmarks.
#[derive(clap::Args)]
struct SphBench {
    #[command(flatten)]
    common: CommonArgs,
    #[command(flatten)]
    sorting: SortArgs,
    #[command(flatten)]
    search: NeighborArgs,
    #[command(flatten)]
    fluid_args: FluidArgs,
}

impl SphBench {
    fn switches(self) -> Switches {
        Switches {
            common: self.common,
            sorting: self.sorting,
            search: self.search,
            fluid_args: self.fluid_args,
            ..Switches::default()
        }
    }
}

impl BenchWhat {
    /// The benchmark's name and its switches (groups it does not take at their defaults).
    /// Long because it is a table: one arm per benchmark naming the groups it takes.
    fn into_parts(
        self,
    ) -> (
        &'static str,
        Switches,
        Option<String>,
        Option<u32>,
        Vec<f32>,
    ) {
        let d = Switches::default;
        let (what, sw) = match self {
            BenchWhat::Skin {
                common,
                character,
                file,
                vertices,
            } => {
                return (
                    "skin",
                    Switches {
                        common,
                        character,
                        ..d()
                    },
                    file,
                    vertices,
                    Vec::new(),
                )
            }
            BenchWhat::Control {
                common,
                control,
                character,
                fluid_args,
                scene,
                velocities,
            } => {
                let sw = Switches {
                    common,
                    control,
                    character,
                    fluid_args,
                    ..d()
                };
                return ("control", sw, scene, None, velocities);
            }
            BenchWhat::Scan { common } => ("scan", Switches { common, ..d() }),
            BenchWhat::Sort { common, sorting } => (
                "sort",
                Switches {
                    common,
                    sorting,
                    ..d()
                },
            ),
            BenchWhat::Neighbors {
                common,
                sorting,
                search,
            } => (
                "neighbors",
                Switches {
                    common,
                    sorting,
                    search,
                    ..d()
                },
            ),
            BenchWhat::Sph(a) => ("sph", a.switches()),
            BenchWhat::Emission {
                common,
                sorting,
                search,
                fluid_args,
                emission,
            } => (
                "emission",
                Switches {
                    common,
                    sorting,
                    search,
                    fluid_args,
                    emission,
                    ..d()
                },
            ),
            BenchWhat::Stability { sph, .. } => ("stability", sph.switches()),
            BenchWhat::Solvers(a) => ("solvers", a.switches()),
            BenchWhat::Particles {
                common,
                frame,
                sorting,
                particle,
            } => (
                "particles",
                Switches {
                    common,
                    frame,
                    sorting,
                    particle,
                    ..d()
                },
            ),
            BenchWhat::Render {
                common,
                frame,
                metaball,
                camera,
            } => (
                "render",
                Switches {
                    common,
                    frame,
                    metaball,
                    camera,
                    ..d()
                },
            ),
        };
        (what, sw, None, None, Vec::new())
    }
}

/// Errors print as one line: the error and any cause its message does not already hold.
fn main() -> std::process::ExitCode {
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
        } => bench_command(what, out, (frames, warmup, budget_s)),
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
            use fluidform::bench::picture::inspect;
            print!("{}", inspect(&file, up, picture.as_deref(), json)?);
            Ok(())
        }
        Command::Experiment {
            name,
            out,
            quick,
            common,
        } => {
            if name == "list" {
                println!("{}", fluidform::experiment::NAMES.join("\n"));
                return Ok(());
            }
            if common.particles.is_some() {
                bail!("experiment: --particles is not used (each experiment sets its own counts)");
            }
            let mut switches = Switches::parse_default();
            switches.common = common;
            let files = fluidform::experiment::run(&fluidform::experiment::ExperimentOptions {
                name,
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

/// `bench`: run one benchmark and print its table.
fn bench_command(
    what: BenchWhat,
    out: PathBuf,
    (frames, warmup, budget_s): (u64, u64, f64),
) -> Result<()> {
    let seconds = match &what {
        BenchWhat::Stability { seconds, .. } => *seconds,
        _ => fluidform::bench::sph::STABILITY_SECONDS,
    };
    let (what, switches, character, vertices, velocities) = what.into_parts();
    let rows = fluidform::bench::run(&fluidform::bench::BenchOptions {
        what: what.to_string(),
        out: out.clone(),
        frames,
        warmup,
        budget_s,
        switches,
        character,
        vertices,
        velocities,
        counts: Vec::new(),
        seconds,
    })?;
    print!("{}", std::fs::read_to_string(out.join("sweep.md"))?);
    eprintln!("{} configurations; wrote {}", rows.len(), out.display());
    Ok(())
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
