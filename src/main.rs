//! The command line: devices | run | bench | experiment.
use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use fluidform::config::Switches;
use fluidform::gpu::list_devices;
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
        /// Built-in scene (dam-break, drop, resting-block, orbits) or a TOML scene file
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
    /// Benchmark an algorithm: scan, sort, neighbors, sph, stability, render.
    /// Without --particles it sweeps N = 8K..1M (scan adds 16M).
    Bench {
        what: String,
        #[arg(long, default_value = "out/bench")]
        out: PathBuf,
        /// Timed repetitions per configuration
        #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..))]
        frames: u64,
        /// Untimed warm-up repetitions
        #[arg(long, default_value_t = 5)]
        warmup: u64,
        /// Seconds one configuration may take; slower ones get fewer repetitions (>= 3)
        #[arg(long, default_value_t = 300.0)]
        budget_s: f64,
        #[command(flatten)]
        switches: Switches,
    },
    /// Reproduce a table of the papers
    Experiment {
        name: String,
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn main() -> Result<()> {
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
                })?;
                println!("{}", ctx.info.slug());
                return Ok(());
            }
            devices(json)
        }
        Command::Run {
            scene,
            frames,
            out,
            save_every,
            switches,
        } => {
            let r = run(&RunOptions {
                scene,
                frames,
                out: out.clone(),
                save_every,
                switches,
            })?;
            print_summary(&r.summary, &out);
            Ok(())
        }
        Command::Bench {
            what,
            out,
            frames,
            warmup,
            budget_s,
            switches,
        } => {
            let rows = fluidform::bench::run(&fluidform::bench::BenchOptions {
                what,
                out: out.clone(),
                frames,
                warmup,
                budget_s,
                switches,
            })?;
            print!("{}", std::fs::read_to_string(out.join("sweep.md"))?);
            eprintln!("{} configurations; wrote {}", rows.len(), out.display());
            Ok(())
        }
        Command::Experiment { name, .. } => {
            bail!("experiment '{name}' is not implemented yet: experiments arrive with the papers' tables")
        }
    }
}

fn devices(json: bool) -> Result<()> {
    let list = list_devices()?;
    if json {
        println!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    if list.is_empty() {
        bail!("no Vulkan device found (run scripts/setup.sh for Mesa lavapipe)");
    }
    for d in &list {
        println!("[{}] {} ({})", d.index, d.name, d.kind);
        println!("    driver: {}  api: {}", d.driver, d.api);
        println!(
            "    timestampPeriod: {} ns  timestampValidBits: {}",
            d.timestamp_period_ns, d.timestamp_valid_bits
        );
        println!(
            "    subgroup size: {}  subgroup arithmetic: {}  maxStorageBufferRange: {}",
            d.subgroup_size, d.subgroup_arithmetic, d.max_storage_buffer_range
        );
        if d.missing.is_empty() {
            println!("    fluidform: all required features present");
        } else {
            println!("    fluidform: UNUSABLE, missing {}", d.missing.join(", "));
        }
    }
    Ok(())
}

fn print_summary(s: &serde_json::Value, out: &std::path::Path) {
    println!(
        "device: {}  frames: {}  GPU frame median {:.3} ms",
        s["device"]["name"].as_str().unwrap_or("?"),
        s["frames"],
        s["frame_ms"]["median"].as_f64().unwrap_or(f64::NAN)
    );
    if let Some(passes) = s["pass_ms"].as_object() {
        for (name, st) in passes {
            println!(
                "  {name:<12} median {:8.3} ms  min {:8.3}  max {:8.3}",
                st["median"].as_f64().unwrap_or(f64::NAN),
                st["min"].as_f64().unwrap_or(f64::NAN),
                st["max"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
    if let Some(v) = s.get("validation") {
        println!(
            "validation: {} errors, {} warnings",
            v["errors"], v["warnings"]
        );
    }
    println!("wrote {}", out.display());
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
