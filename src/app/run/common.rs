//! What `run`, `bench`, `experiment` and the window share: opening the device, the
//! camera switches, failing on validation errors, and playing frames of a `FrameWork`.
use crate::config::Switches;
use crate::error::{Error, Result};
use crate::gpu::ScopeDepth;
use crate::gpu::{Context, ContextOptions, FrameLoop, FrameTiming, FrameWork};
use crate::render::Camera;

/// Frames in flight.
pub const SLOTS: usize = 2;

pub fn open(sw: &Switches) -> Result<Context> {
    Context::new(&ContextOptions {
        device: sw.common.device.clone(),
        validation: sw.common.validation,
        present: None,
    })
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

/// The camera with --eye, --target and --fov applied.
pub fn camera_with_switches(mut cam: Camera, sw: &Switches) -> Camera {
    if let Some(e) = sw.camera.eye {
        cam.eye = e.into();
    }
    if let Some(t) = sw.camera.target {
        cam.target = t.into();
    }
    if let Some(f) = sw.camera.fov {
        cam.fov_y_deg = f;
    }
    cam
}

/// Play `frames` frames of `work` with `SLOTS` in flight, reporting progress as `what`
/// unless `quiet`; the GPU timings of every frame (every scope timed).
pub fn play(
    ctx: &Context,
    frames: u64,
    work: &mut dyn FrameWork,
    what: &str,
    quiet: bool,
) -> Result<Vec<FrameTiming>> {
    play_scoped(ctx, frames, work, what, quiet, ScopeDepth::All)
}

/// `play` for `run`: quiet and timing the scopes as the switches say (`--quiet`, `--scopes`).
pub fn play_run(
    ctx: &Context,
    frames: u64,
    work: &mut dyn FrameWork,
    what: &str,
    common: &crate::config::CommonArgs,
) -> Result<Vec<FrameTiming>> {
    let scopes = common.scopes.unwrap_or(ScopeDepth::All);
    play_scoped(ctx, frames, work, what, common.quiet, scopes)
}

/// `play`, timing only the scopes `scopes` asks for (`run --scopes`).
fn play_scoped(
    ctx: &Context,
    frames: u64,
    work: &mut dyn FrameWork,
    what: &str,
    quiet: bool,
    scopes: ScopeDepth,
) -> Result<Vec<FrameTiming>> {
    let mut fl = FrameLoop::new(ctx, SLOTS)?;
    fl.profiler.time_scopes(scopes);
    let mut reporting = crate::progress::Reporting {
        work,
        progress: crate::progress::Progress::new(what, frames, quiet),
    };
    let r = fl.run(ctx, frames, &mut reporting);
    reporting.progress.finish();
    let timings = std::mem::take(&mut fl.profiler.results);
    fl.destroy(ctx);
    r.map(|_| timings)
}
