//! `fluidform view`: a scene in a window. The frames are `run`'s (the same `SphWork`,
//! stepped by the same `FrameLoop`); the window adds a swapchain that shows each frame's
//! picture, a camera, and an overlay panel whose controls, the keys and `--at` scripts
//! all go through one command interface (`command`).
pub mod command;
pub mod flags;
mod input;
mod orbit;
mod panel;
mod session;

use crate::config::Switches;
use crate::error::{Error, Result};
use crate::gpu::present::{PresentMode, Presenter};
use crate::gpu::{Context, ContextOptions};
use command::Command;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::path::PathBuf;
use std::time::{Duration, Instant};
use winit::platform::pump_events::{EventLoopExtPumpEvents, PumpStatus};

/// `fluidform view`'s command line.
#[derive(clap::Args)]
pub struct WindowArgs {
    /// A built-in scene (SPH scenes) or a TOML scene file
    #[arg(long, default_value = crate::run::DEFAULT_SCENE)]
    pub scene: String,
    /// How frames reach the display
    #[arg(long, value_enum, default_value = "fifo")]
    pub present: PresentArg,
    /// Close after N frames (scripts and tests)
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// On closing: the last frame's picture (without the panel) as a PNG
    #[arg(long, value_name = "FILE")]
    pub screenshot: Option<PathBuf>,
    /// Carry out a command before frame F, as a key would: "3:set list sbuffer",
    /// "5:pause", "8:screenshot a.png 640x480" (repeatable)
    #[arg(long, value_name = "F:COMMAND", value_parser = command::parse_at)]
    pub at: Vec<(u64, Command)>,
    /// Start with the panel hidden (Tab shows it)
    #[arg(long)]
    pub hide_panel: bool,
    #[command(flatten)]
    pub switches: Switches,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum PresentArg {
    Fifo,
    Mailbox,
    Immediate,
}

impl From<WindowArgs> for ViewOptions {
    fn from(a: WindowArgs) -> Self {
        Self {
            scene: a.scene,
            present: match a.present {
                PresentArg::Fifo => PresentMode::Fifo,
                PresentArg::Mailbox => PresentMode::Mailbox,
                PresentArg::Immediate => PresentMode::Immediate,
            },
            frames: a.frames,
            screenshot: a.screenshot,
            at: a.at,
            hide_panel: a.hide_panel,
            switches: a.switches,
        }
    }
}

pub struct ViewOptions {
    pub scene: String,
    pub present: PresentMode,
    /// Close after this many frames (scripts, tests).
    pub frames: Option<u64>,
    /// With `frames`: the last frame's picture to this PNG.
    pub screenshot: Option<PathBuf>,
    /// Commands carried out before a frame: (frame, command).
    pub at: Vec<(u64, Command)>,
    pub hide_panel: bool,
    pub switches: Switches,
}

/// The window's size when the switches give none.
pub const DEFAULT_SIZE: (u32, u32) = (1280, 720);

/// The window could not open: say how to run without one.
fn no_display(e: impl std::fmt::Display) -> Error {
    Error::Unsupported(format!(
        "view needs a display ({e}); without one, run headless with `fluidform run` (same \
         switches), or under a virtual display: xvfb-run -a fluidform view ..."
    ))
}

/// Open the window and play until it closes (or `frames` frames have played).
pub fn view(opts: ViewOptions) -> Result<()> {
    opts.switches.all_scopes("view (its panel)")?;
    if std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        return Err(no_display("DISPLAY is not set"));
    }
    let mut event_loop = winit::event_loop::EventLoop::new().map_err(no_display)?;
    let display = event_loop.display_handle().map_err(no_display)?.as_raw();
    let sw = &opts.switches;
    if sw.frame.grid() > 1 {
        return Err(Error::Param(
            "--samples supersamples saved pictures (run); the window draws one sample a pixel"
                .into(),
        ));
    }
    let size = match (sw.frame.width, sw.frame.height) {
        (None, None) => DEFAULT_SIZE,
        _ => (sw.frame.width(), sw.frame.height()),
    };
    let ctx = Context::new(&ContextOptions {
        device: sw.common.device.clone(),
        validation: sw.common.validation,
        present: Some(display),
    })?;
    let mut input = input::Input::new(size);
    // The window opens on the first events (winit's `resumed`).
    for _ in 0..100 {
        if let PumpStatus::Exit(_) =
            event_loop.pump_app_events(Some(Duration::from_millis(10)), &mut input)
        {
            break;
        }
        if input.window.is_some() || input.error.is_some() {
            break;
        }
    }
    let window = match (input.window.as_ref(), input.error.take()) {
        (Some(w), None) => w,
        (_, e) => return Err(no_display(e.unwrap_or_else(|| "no window opened".into()))),
    };
    let inner = window.inner_size();
    let size = (inner.width.max(1), inner.height.max(1));
    let handle = window.window_handle().map_err(no_display)?.as_raw();
    let mut presenter = Presenter::new(&ctx, display, handle, opts.present, size)?;
    let played = (|| {
        let mut overlay = crate::gpu::overlay::Overlay::new(&ctx, presenter.format)?;
        let mut args = flags::args_of(&opts.switches);
        // The window, not --width/--height, sizes the picture.
        args = flags::with(&args, "width", None);
        args = flags::with(&args, "height", None);
        let s = session::Session::new(&ctx, &opts.scene, args, size);
        let mut s = match s {
            Ok(s) => s,
            Err(e) => {
                overlay.destroy(&ctx);
                return Err(e);
            }
        };
        let r = play(
            &ctx,
            &opts,
            &mut event_loop,
            &mut input,
            &mut presenter,
            &mut overlay,
            &mut s,
        );
        s.destroy(&ctx);
        overlay.destroy(&ctx);
        r
    })();
    presenter.destroy(&ctx);
    let walls = played?;
    crate::run::common::check_validation(&ctx)?;
    // Resizes, rebuilds and resets make and free buffers: none may be left over.
    let (mem, objects) = (ctx.memory_bytes(), ctx.live_objects());
    if !mem.is_empty() || !objects.is_empty() {
        return Err(Error::Memory(format!(
            "view left GPU objects behind: {mem:?} {objects:?}"
        )));
    }
    println!("{}", walls.describe());
    Ok(())
}

/// The window's frame times, for the closing line.
#[derive(Default)]
struct Walls {
    played: u64,
    wall_ms: Vec<f64>,
    gpu_ms: Vec<f64>,
}

impl Walls {
    fn describe(mut self) -> String {
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied()
        };
        match (median(&mut self.wall_ms), median(&mut self.gpu_ms)) {
            (Some(w), Some(g)) => format!(
                "view: {} frames; median {w:.2} ms a window frame, GPU frame median {g:.2} ms \
                 (frames 4 on)",
                self.played
            ),
            _ => format!(
                "view: {} frames (too few after the first 3 for medians)",
                self.played
            ),
        }
    }
}

/// The window's frames: events, commands, the scene's frame, the overlay, present.
#[allow(clippy::too_many_arguments)]
fn play(
    ctx: &Context,
    opts: &ViewOptions,
    event_loop: &mut winit::event_loop::EventLoop<()>,
    input: &mut input::Input,
    presenter: &mut Presenter,
    overlay: &mut crate::gpu::overlay::Overlay,
    s: &mut session::Session,
) -> Result<Walls> {
    let mut walls = Walls::default();
    let mut panel_state = panel::PanelState::default();
    panel_state.shown = !opts.hide_panel;
    let all_flags = flags::all();
    let mut played = 0u64;
    let mut last = Instant::now();
    let mut wall_ms = 0.0;
    loop {
        if let PumpStatus::Exit(_) = event_loop.pump_app_events(Some(Duration::ZERO), input) {
            break;
        }
        if input.close || s.quit {
            break;
        }
        let mut commands: Vec<Command> = std::mem::take(&mut input.commands);
        let scripted = opts.at.iter().filter(|(f, _)| *f == played);
        commands.splice(0..0, scripted.map(|(_, c)| c.clone()));
        for c in commands {
            if c == Command::TogglePanel {
                panel_state.shown = !panel_state.shown;
            }
            s.apply(ctx, c, input.window.as_ref())?;
        }
        let m = std::mem::take(&mut input.motion);
        let height = s.size.1 as f32;
        s.orbit.rotate(m.rotate.0, m.rotate.1);
        s.orbit.pan(m.pan.0, m.pan.1, height);
        s.orbit.zoom(m.zoom);
        let walk = input.walk();
        if s.orbit.fly && walk != [0.0; 3] {
            let d = s.orbit.scale() * 0.5 * (wall_ms as f32 / 1000.0).min(0.1);
            s.orbit.walk(glam::Vec3::from(walk) * d);
        }
        if let Some(new) = input.resized.take() {
            presenter.resize(ctx, new)?;
            s.resize(ctx, new)?;
        }
        if presenter.stale() {
            // Minimised (no area) or out of date: try again shortly, play nothing.
            let inner = input.window.as_ref().map(|w| w.inner_size());
            if let Some(i) = inner.filter(|i| i.width > 0 && i.height > 0) {
                presenter.resize(ctx, (i.width, i.height))?;
            }
            std::thread::sleep(Duration::from_millis(20));
            if presenter.stale() {
                continue;
            }
        }
        s.frame(ctx)?;
        played += 1;
        walls.played = played;
        let stats = s.live.stats(ctx);
        let events = s.live.events();
        let values = serde_json::to_value(&s.live.sw).unwrap_or_default();
        let view = panel::PanelView {
            scene: &s.scene,
            frame: s.live.frame,
            paused: s.paused,
            speed: s.speed,
            recording: s.recording.is_some(),
            fly: s.orbit.fly,
            wall_ms,
            stats: &stats,
            timings: &s.live.frames.profiler.results,
            events: &events,
            flags: &all_flags,
            sw: &values,
            args: &s.args,
            message: &s.message,
        };
        let mut asked = Vec::new();
        let (Some(window), Some(egui_state)) = (input.window.as_ref(), input.egui.as_mut()) else {
            break;
        };
        let raw = egui_state.take_egui_input(window);
        let out = input
            .egui_ctx
            .run(raw, |c| panel::ui(c, &mut panel_state, &view, &mut asked));
        egui_state.handle_platform_output(window, out.platform_output.clone());
        input.commands.extend(asked);
        overlay.prepare(ctx, presenter.command_pool(), &input.egui_ctx, out)?;
        let picture = s.live.picture();
        presenter.present(ctx, picture, &mut |cmd, extent| overlay.draw(cmd, extent))?;
        s.record_frame()?;
        let now = Instant::now();
        wall_ms = (now - last).as_secs_f64() * 1000.0;
        last = now;
        // The first frames build pipelines and fill the queue: not counted.
        if played > 3 {
            walls.wall_ms.push(wall_ms);
            let gpu = s.live.frames.profiler.results.last();
            walls.gpu_ms.extend(gpu.map(|t| t.frame_ms));
        }
        if opts.frames.is_some_and(|n| played >= n) {
            break;
        }
    }
    if let Some(path) = &opts.screenshot {
        s.apply(ctx, Command::Screenshot(path.clone(), None), None)?;
        if s.message.starts_with("error") {
            return Err(Error::Param(format!("--screenshot: {}", s.message)));
        }
    }
    Ok(walls)
}
