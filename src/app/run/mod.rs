//! `fluidform run`: play a scene for N frames, write PNGs, timings.csv and summary.json.
//! Every scene kind is a `FrameWork` played by `common::play`.
use crate::animation::Animation;
use crate::character::Skinning;
use crate::config::Switches;
use crate::error::{Error, Result};
use crate::gpu::target::save_rgba;
use crate::gpu::vk;
use crate::gpu::{Context, FrameWork, Guard, Profiler};
use crate::kinds::{Neighbors, SortAlgo};
use crate::render::Camera;
use crate::render::{RenderKind, ShowMesh};
use crate::report::{Report, Summary};
pub use crate::run::common::{camera_with_switches, check_validation, SLOTS};
use crate::run::common::{open, play_run};
use crate::run::targets::character::{CharacterStats, SceneCharacter};
use crate::run::view::{FluidView, Picture, PointsViewer};
use crate::sph::FluidParams;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

mod character;
pub mod common;
pub mod live;
mod orbits;
pub mod particles;
mod sph;
pub mod targets;
pub mod view;
use character::run_character;
use orbits::run_orbits;
use sph::run_sph;

pub struct RunOptions {
    pub scene: String,
    /// Frames to play; None: the scene's own count (orbits: 120).
    pub frames: Option<u64>,
    pub out: PathBuf,
    /// Save every k-th frame as PNG; 0 saves none.
    pub save_every: u64,
    pub switches: Switches,
}

pub const DEFAULT_SCENE: &str = "character";

/// `config` of a run's summary.json.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunConfig {
    pub command: String,
    pub scene: String,
    pub frames: u64,
    pub save_every: u64,
    pub particles: u64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub neighbors: Option<Neighbors>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sort: Option<SortAlgo>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub render: Option<RenderKind>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fluid: Option<FluidParams>,
    pub switches: Switches,
}

/// `stats` of the orbits scene.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct OrbitsStats {
    pub particles: u32,
}

/// `stats` of a scene with a character and no fluid.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CharacterRunStats {
    pub character: CharacterStats,
    pub render: crate::run::view::RenderSummary,
}

/// `stats` of an SPH run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SphRunStats {
    #[serde(flatten)]
    pub physics: crate::sph::stepper::PhysicsStats,
    pub steps: u64,
    pub simulated_seconds: f64,
    pub render: crate::run::view::RenderSummary,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character: Option<crate::run::targets::character::CharacterStats>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<crate::run::targets::ControlSummary>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<crate::run::targets::emission::EmissionStats>,
    /// The density error of every step (per step in steps.csv).
    #[serde(default)]
    pub density_error: crate::sph::errors::DensityErrorStats,
    /// Dispatches, barriers and empty dispatches per step.
    #[serde(default)]
    pub commands: crate::sph::commands::CommandStats,
    /// The scene's particle systems, if any.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub particle_systems: Vec<crate::run::particles::SystemStats>,
}

/// `stats` of a run, tagged by its scene kind (`kind`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum RunStats {
    Sph(Box<SphRunStats>),
    Character(Box<CharacterRunStats>),
    Orbits(OrbitsStats),
    Particles(Box<crate::run::particles::ParticleRunStats>),
}

pub type RunSummary = Summary<RunConfig, RunStats>;

impl RunStats {
    /// The renderer's block, where the scene renders a fluid or a character.
    pub fn render(&self) -> Option<&crate::run::view::RenderSummary> {
        match self {
            RunStats::Sph(s) => Some(&s.render),
            RunStats::Character(c) => Some(&c.render),
            _ => None,
        }
    }

    /// The SPH run's block.
    pub fn sph(&self) -> Option<&SphRunStats> {
        match self {
            RunStats::Sph(s) => Some(s),
            _ => None,
        }
    }
}

/// The run's outcome: the summary written and the frames saved.
pub struct RunResult {
    pub summary: RunSummary,
    pub pngs: Vec<PathBuf>,
    /// animation.png (APNG) of the saved frames, when any were saved.
    pub animation: Option<PathBuf>,
    /// Particle files written by --export.
    pub exports: Vec<PathBuf>,
}

/// Frames per second the animation plays at.
pub const ANIMATION_FPS: u16 = 30;

/// Where saved frames go: frame_NNNN.png each, and animation.png (APNG) of them all; in
/// a window, every frame's picture is also kept for the swapchain.
pub(crate) struct Frames {
    out: PathBuf,
    every: u64,
    /// Frames the run plays.
    total: u64,
    pngs: Vec<PathBuf>,
    animation: Option<Animation>,
    /// The newest picture (RGBA8, width, height), when every frame is kept.
    pub(crate) latest: Option<(Vec<u8>, u32, u32)>,
    keep: bool,
    /// The sample grid's side: pictures come rendered this many times larger.
    grid: u32,
}

impl Frames {
    pub(crate) fn new(out: &Path, every: u64, total: u64) -> Self {
        Self {
            out: out.to_path_buf(),
            every,
            total,
            pngs: Vec::new(),
            animation: None,
            latest: None,
            keep: false,
            grid: 1,
        }
    }

    /// Pictures rendered with `frame`'s sample grid (`--samples`), saved at its size.
    pub(crate) fn sampled(self, frame: &crate::config::FrameArgs) -> Self {
        Self {
            grid: frame.grid(),
            ..self
        }
    }

    /// Keep every frame's picture (a window shows it) and write none.
    pub(crate) fn kept() -> Self {
        Self {
            keep: true,
            ..Self::new(Path::new(""), 0, 1)
        }
    }

    /// Whether frame `f`'s picture is read back.
    pub(crate) fn save(&self, f: u64) -> bool {
        self.keep || (self.every > 0 && f.is_multiple_of(self.every))
    }

    /// Write frame `f`'s picture as a PNG and as the animation's next frame (or keep it).
    pub(crate) fn store(&mut self, f: u64, pic: Option<Picture>) -> Result<()> {
        let Some(pic) = pic else { return Ok(()) };
        if self.keep {
            let l = self.latest.get_or_insert_with(|| (Vec::new(), 0, 0));
            l.0.clear();
            l.0.extend_from_slice(pic.rgba);
            (l.1, l.2) = (pic.width, pic.height);
            return Ok(());
        }
        let down;
        let pic = match self.grid {
            1 => pic,
            k => {
                down = box_filter(pic.rgba, (pic.width, pic.height), k);
                Picture {
                    rgba: &down,
                    width: pic.width / k,
                    height: pic.height / k,
                }
            }
        };
        let path = self.out.join(format!("frame_{f:04}.png"));
        save_rgba(&path, pic.width, pic.height, pic.rgba)?;
        self.pngs.push(path);
        if self.animation.is_none() {
            let saved = (self.total - 1) / self.every + 1;
            self.animation = Some(Animation::create(
                &self.out.join("animation.png"),
                pic.width,
                pic.height,
                saved as u32,
                ANIMATION_FPS,
            )?);
        }
        if let Some(a) = &mut self.animation {
            a.add(pic.rgba, pic.width, pic.height)?;
        }
        Ok(())
    }

    /// Close the animation; its path, when frames were saved.
    fn finish(&mut self) -> Result<Option<PathBuf>> {
        self.animation.take().map(Animation::finish).transpose()
    }
}

/// RGBA8 (gamma 2.2) `size` averaged over k x k blocks in linear light.
fn box_filter(rgba: &[u8], (w, h): (u32, u32), k: u32) -> Vec<u8> {
    let lin: Vec<f32> = (0..256).map(|v| (v as f32 / 255.0).powf(2.2)).collect();
    let (ow, oh) = (w / k, h / k);
    let mut out = Vec::with_capacity((ow * oh * 4) as usize);
    for y in 0..oh {
        for x in 0..ow {
            let mut sum = [0.0f32; 4];
            for dy in 0..k {
                for dx in 0..k {
                    let i = (((y * k + dy) * w + x * k + dx) * 4) as usize;
                    for (c, v) in sum.iter_mut().zip(&rgba[i..i + 3]) {
                        *c += lin[*v as usize];
                    }
                    sum[3] += rgba[i + 3] as f32;
                }
            }
            let n = (k * k) as f32;
            for c in &sum[..3] {
                out.push(((c / n).powf(1.0 / 2.2) * 255.0).round() as u8);
            }
            out.push((sum[3] / n).round() as u8);
        }
    }
    out
}

/// The metaball radius at the default particle spacing (MetaballSettings' default).
const DEFAULT_RADIUS: f32 = 0.04;

pub fn run(opts: &RunOptions) -> Result<RunResult> {
    if opts.frames == Some(0) {
        return Err(Error::Param("--frames must be at least 1".into()));
    }
    std::fs::create_dir_all(&opts.out).map_err(|e| Error::Io {
        path: opts.out.display().to_string(),
        source: e,
    })?;
    if opts.scene == "orbits" {
        return run_orbits(opts);
    }
    if let Some(scene) = crate::scene::particles::ParticleScene::find(&opts.scene)? {
        return crate::run::particles::run(opts, scene);
    }
    let scene = crate::scene::Scene::load(&opts.scene)?;
    match scene.has_fluid() {
        true => run_sph(opts, scene),
        false => run_character(opts, scene),
    }
}

/// The end of a run without fluid (orbits, a character alone): the animation closed,
/// summary.json written, validation checked.
pub(crate) fn finish_fluidless(
    ctx: &Context,
    opts: &RunOptions,
    sw: &Switches,
    (scene, frames, particles): (&str, u64, u64),
    (timings, memory): (
        &[crate::gpu::FrameTiming],
        std::collections::BTreeMap<String, u64>,
    ),
    stats: RunStats,
    mut saved: Frames,
) -> Result<RunResult> {
    let animation = saved.finish()?;
    let config = RunConfig {
        command: "run".into(),
        scene: scene.to_string(),
        frames,
        save_every: opts.save_every,
        particles,
        neighbors: None,
        sort: None,
        render: None,
        fluid: None,
        switches: sw.clone(),
    };
    let report = Report {
        device: &ctx.info,
        config,
        timings,
        memory,
        stats,
        validation: sw.common.validation.then(|| ctx.validation_counts()),
        barriers: ctx.tracked_barriers(),
    };
    let summary = report.write(&opts.out)?;
    if let Some(path) = &sw.common.trace {
        crate::trace::write_run_trace(ctx, path, timings)?;
    }
    check_validation(ctx)?;
    Ok(RunResult {
        summary,
        pngs: saved.pngs,
        animation,
        exports: Vec::new(),
    })
}

/// The run's device, GPU frame median, pass medians and validation counts on stdout.
pub fn print_summary(s: &RunSummary) {
    println!(
        "device: {}  frames: {}  GPU frame median {:.3} ms",
        s.device.name,
        s.frames,
        s.frame_ms.map(|f| f.median).unwrap_or(f64::NAN)
    );
    for (name, st) in &s.pass_ms.0 {
        println!(
            "  {name:<24} median {:8.3} ms  min {:8.3}  max {:8.3}",
            st.median, st.min, st.max
        );
    }
    if let Some(v) = &s.validation {
        println!("validation: {} errors, {} warnings", v.errors, v.warnings);
    }
    if let Some(line) = host_paced(s) {
        println!("{line}");
    }
}

/// Where the wall clock's frame (`wall_ms`) is more than 1.25x the GPU's (`frame_ms`):
/// the host, not the GPU, set the run's pace.
pub fn host_paced(s: &RunSummary) -> Option<String> {
    let (wall, gpu) = (s.wall_ms?.median, s.frame_ms?.median);
    (wall > 1.25 * gpu).then(|| {
        format!(
            "the host set the pace: {wall:.3} ms a frame of wall time against {gpu:.3} ms of GPU \
             time ({:.2}x; per-frame CPU work such as the fidelity metrics)",
            wall / gpu
        )
    })
}
