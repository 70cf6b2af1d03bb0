//! `fluidform run`: play a scene for N frames, write PNGs, timings.csv and summary.json.
use crate::config::Switches;
use crate::error::{Error, Result};
use crate::gpu::{ColorTarget, Context, ContextOptions, FrameLoop};
use crate::render::{points::PointsPush, Camera, PointsView};
use crate::report::Report;
use crate::scene::orbits::{self, Orbits, OrbitsPass};
use serde_json::{json, Value};
use std::path::PathBuf;

/// Frames in flight.
pub const SLOTS: usize = 2;

pub struct RunOptions {
    pub scene: String,
    pub frames: u64,
    pub out: PathBuf,
    /// Save every k-th frame as PNG; 0 saves none.
    pub save_every: u64,
    pub switches: Switches,
}

pub const SCENES: &[&str] = &["orbits"];
pub const DEFAULT_SCENE: &str = "orbits";

/// The run's outcome: the summary written and the validation counts.
pub struct RunResult {
    pub summary: Value,
    pub pngs: Vec<PathBuf>,
}

pub fn run(opts: &RunOptions) -> Result<RunResult> {
    if opts.frames == 0 {
        return Err(Error::Param("--frames must be at least 1".into()));
    }
    if opts.scene != "orbits" {
        let hint = if opts.scene.ends_with(".toml") {
            "scene files arrive with the SPH scenes (issue 4)".to_string()
        } else {
            format!("built-in scenes: {}", SCENES.join(", "))
        };
        return Err(Error::Param(format!(
            "unknown scene '{}': {hint}",
            opts.scene
        )));
    }
    let sw = &opts.switches;
    sw.reject_unimplemented("the orbits scene", &[])?;
    let ctx = Context::new(&ContextOptions {
        device: sw.device.clone(),
        validation: sw.validation,
    })?;
    let particles = sw.particles.unwrap_or(4096);
    std::fs::create_dir_all(&opts.out).map_err(|e| Error::Io {
        path: opts.out.display().to_string(),
        source: e,
    })?;

    let state = orbits::initial_state(particles as usize, sw.seed);
    let mut pass = OrbitsPass::new(&ctx)?;
    let mut view = PointsView::new(&ctx)?;
    let mut scene = Orbits::new(&ctx, &state)?;
    let mut target = ColorTarget::new(&ctx, sw.width, sw.height, SLOTS)?;
    let mut frames = FrameLoop::new(&ctx, SLOTS, 16)?;
    let cam = Camera::look_at(
        glam::Vec3::new(0.0, 0.8, 3.2),
        glam::Vec3::ZERO,
        45.0,
        sw.width as f32 / sw.height as f32,
    );
    let push = PointsPush::from_camera(&cam, 1.0);
    let memory = ctx.memory_bytes();
    let save = |f: u64| opts.save_every > 0 && f % opts.save_every == 0;
    let mut pngs = Vec::new();
    let result = frames.run(
        &ctx,
        opts.frames,
        |prof, cmd, frame, slot| {
            prof.begin(&ctx, cmd, OrbitsPass::NAME);
            pass.step(&ctx, cmd, &scene, 1.0 / 120.0);
            prof.end(&ctx, cmd);
            ctx.barrier(cmd);
            prof.begin(&ctx, cmd, PointsView::NAME);
            target.begin_rendering(&ctx, cmd, [0.02, 0.02, 0.04, 1.0]);
            view.draw(&ctx, cmd, &scene.pos, &scene.color, scene.n, &push);
            target.end_rendering(&ctx, cmd);
            prof.end(&ctx, cmd);
            if save(frame) {
                prof.begin(&ctx, cmd, "readback");
                target.copy_out(&ctx, cmd, slot);
                prof.end(&ctx, cmd);
            }
            Ok(())
        },
        |frame, slot| {
            if save(frame) {
                let path = opts.out.join(format!("frame_{frame:04}.png"));
                target.save_png(slot, &path)?;
                pngs.push(path);
            }
            Ok(())
        },
    );
    let timings = std::mem::take(&mut frames.profiler.results);
    frames.destroy(&ctx);
    target.destroy(&ctx);
    scene.destroy(&ctx);
    view.destroy(&ctx);
    pass.destroy(&ctx);
    result?;

    let validation = sw.validation.then(|| ctx.validation_counts());
    let config = json!({
        "command": "run",
        "scene": opts.scene,
        "frames": opts.frames,
        "save_every": opts.save_every,
        "particles": particles,
        "switches": sw,
    });
    let report = Report {
        device: &ctx.info,
        config,
        timings: &timings,
        memory,
        stats: json!({ "particles": particles }),
        validation,
    };
    let summary = report.write(&opts.out)?;
    check_validation(&ctx)?;
    Ok(RunResult { summary, pngs })
}

/// With validation on, any validation error fails the command.
pub fn check_validation(ctx: &Context) -> Result<()> {
    let (errors, _) = ctx.validation_counts();
    if errors > 0 {
        return Err(Error::Unsupported(format!(
            "{errors} Vulkan validation error(s); first: {}",
            ctx.validation_messages()
                .first()
                .cloned()
                .unwrap_or_default()
        )));
    }
    Ok(())
}
