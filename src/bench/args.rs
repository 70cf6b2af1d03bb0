//! The `bench` subcommands, each with only the switch groups it uses, and the run of one.
use super::Bench;
use crate::config::{
    CameraArgs, CharacterArgs, CommonArgs, ControlArgs, EmissionArgs, FluidArgs, FrameArgs,
    MetaballArgs, NeighborArgs, ParticleArgs, SortArgs, Switches,
};
use crate::error::Result;
use clap::Subcommand;
use std::path::PathBuf;

/// The benchmarks, each with only the switches it uses.
#[derive(Subcommand)]
pub enum BenchWhat {
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
        #[arg(long, default_value_t = crate::bench::sph::STABILITY_SECONDS)]
        seconds: f64,
    },
    /// The dam break per pressure solver (or --solver) at 16K, 64K, 256K (or --particles):
    /// each at its own stable step and at mean density error <= 1% and <= 0.1%; times
    /// --frames frames of 20 ms after --warmup frames
    Solvers(SphBench),
    /// The inside test (crossings on a closed mesh, the winding number on an open one)
    /// voxelising a character at the fit's finest spacing, as loaded and refined to about
    /// --triangles triangles with holes cut (CPU; --frames timed rounds)
    Inside {
        #[command(flatten)]
        common: CommonArgs,
        /// Character file (.glb, .gltf, .obj) or builtin:walker (the default)
        #[arg(long = "character", value_name = "FILE")]
        file: Option<String>,
        /// Triangles of the refined, open copy (default 50000)
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=(1 << 24)))]
        triangles: Option<u32>,
    },
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
        control: ControlArgs,
        #[command(flatten)]
        character: CharacterArgs,
        #[command(flatten)]
        fluid_args: FluidArgs,
        /// Scene with a `[control]` target (built-in name or TOML file; default giraffe)
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
        emission: EmissionArgs,
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
        particle: ParticleArgs,
    },
    /// The metaball renderer on a resting blob, per list (or --list)
    Render(RenderBench),
    /// The march's own costs on the resting blob: counters (subgroup, workgroup, off) and
    /// lanes (blocks, rows), each switched alone, per list (or --list)
    March(RenderBench),
}

/// The switches of the rendering benchmarks.
#[derive(clap::Args)]
pub struct RenderBench {
    #[command(flatten)]
    common: CommonArgs,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    metaball: MetaballArgs,
    #[command(flatten)]
    camera: CameraArgs,
}

impl RenderBench {
    fn switches(self) -> Switches {
        Switches {
            common: self.common,
            frame: self.frame,
            metaball: self.metaball,
            camera: self.camera,
            ..Switches::default()
        }
    }
}

/// The switches of the SPH benchmarks.
#[derive(clap::Args)]
pub struct SphBench {
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
    fn into_parts(self) -> (Bench, Switches, Option<String>, Option<u32>, Vec<f32>) {
        let d = Switches::default;
        let (what, sw) = match self {
            BenchWhat::Inside {
                common,
                file,
                triangles,
            } => {
                let sw = Switches { common, ..d() };
                return (Bench::Inside, sw, file, triangles, Vec::new());
            }
            BenchWhat::Skin {
                common,
                character,
                file,
                vertices,
            } => {
                return (
                    Bench::Skin,
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
                return (Bench::Control, sw, scene, None, velocities);
            }
            BenchWhat::Scan { common } => (Bench::Scan, Switches { common, ..d() }),
            BenchWhat::Sort { common, sorting } => (
                Bench::Sort,
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
                Bench::Neighbors,
                Switches {
                    common,
                    sorting,
                    search,
                    ..d()
                },
            ),
            BenchWhat::Sph(a) => (Bench::Sph, a.switches()),
            BenchWhat::Emission {
                common,
                sorting,
                search,
                fluid_args,
                emission,
            } => (
                Bench::Emission,
                Switches {
                    common,
                    sorting,
                    search,
                    fluid_args,
                    emission,
                    ..d()
                },
            ),
            BenchWhat::Stability { sph, .. } => (Bench::Stability, sph.switches()),
            BenchWhat::Solvers(a) => (Bench::Solvers, a.switches()),
            BenchWhat::Particles {
                common,
                frame,
                sorting,
                particle,
            } => (
                Bench::Particles,
                Switches {
                    common,
                    frame,
                    sorting,
                    particle,
                    ..d()
                },
            ),
            BenchWhat::Render(r) => (Bench::Render, r.switches()),
            BenchWhat::March(r) => (Bench::March, r.switches()),
        };
        (what, sw, None, None, Vec::new())
    }
}

/// How a benchmark times its configurations (the protocol's knobs).
pub struct Timing {
    pub frames: u64,
    pub warmup: u64,
    pub budget_s: f64,
    pub rounds: u64,
    pub warmup_s: f64,
    /// Percent (see `BenchOptions::drift`).
    pub drift: f64,
}

/// `bench`: run one benchmark; where its table went and how many configurations it has.
pub fn run(what: BenchWhat, out: PathBuf, t: Timing) -> Result<(PathBuf, usize)> {
    if !(t.warmup_s.is_finite() && t.warmup_s >= 0.0) {
        return Err(crate::Error::Param(format!(
            "--warmup-s must be a number of seconds >= 0 (got {})",
            t.warmup_s
        )));
    }
    if !(t.drift.is_finite() && t.drift > 0.0) {
        return Err(crate::Error::Param(format!(
            "--drift must be a percentage > 0 (got {})",
            t.drift
        )));
    }
    let seconds = match &what {
        BenchWhat::Stability { seconds, .. } => *seconds,
        _ => crate::bench::sph::STABILITY_SECONDS,
    };
    let (what, switches, character, vertices, velocities) = what.into_parts();
    let rows = crate::bench::run(&crate::bench::BenchOptions {
        what: super::Measurer::Bench(what),
        out: out.clone(),
        frames: t.frames,
        warmup: t.warmup,
        budget_s: t.budget_s,
        rounds: t.rounds,
        warmup_s: t.warmup_s,
        drift: t.drift / 100.0,
        switches,
        character,
        vertices,
        velocities,
        counts: Vec::new(),
        seconds,
    })?;
    Ok((out, rows.len()))
}
