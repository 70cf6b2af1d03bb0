//! The viewer's state and how each command is carried out: switch flips (the view rebuilt
//! live, or the scene rebuilt, said so), playback, seeking, camera, screenshots, recording.
use super::command::Command;
use super::flags;
use super::orbit::Orbit;
use crate::config::Switches;
use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::run::live::LiveScene;
use std::path::{Path, PathBuf};

pub struct Session {
    pub live: LiveScene,
    pub scene: String,
    /// The switches the user gave or flipped, as flags (the run command line).
    pub args: Vec<String>,
    pub orbit: Orbit,
    pub paused: bool,
    step_once: bool,
    pub speed: f64,
    /// The last command's outcome, shown in the panel.
    pub message: String,
    /// Recording: the folder and frames written so far.
    pub recording: Option<(PathBuf, u32)>,
    /// The picture's size: the window's inner size.
    pub size: (u32, u32),
    pub quit: bool,
    clipboard: Option<arboard::Clipboard>,
}

/// `sw` drawing frames of `size`.
fn sized(sw: &Switches, size: (u32, u32)) -> Switches {
    let mut sw = sw.clone();
    (sw.frame.width, sw.frame.height) = (Some(size.0), Some(size.1));
    sw
}

impl Session {
    pub fn new(ctx: &Context, scene: &str, args: Vec<String>, size: (u32, u32)) -> Result<Self> {
        let sw = flags::parse(&args).map_err(Error::Param)?;
        let live = LiveScene::open(ctx, scene, &sized(&sw, size))?;
        Ok(Self {
            orbit: Orbit::new(live.home),
            live,
            scene: scene.to_string(),
            args,
            paused: false,
            step_once: false,
            speed: 1.0,
            message: String::new(),
            recording: None,
            size,
            quit: false,
            clipboard: None,
        })
    }

    /// Play the next window frame (simulated unless paused; a step simulates one).
    pub fn frame(&mut self, ctx: &Context) -> Result<()> {
        let aspect = self.size.0 as f32 / self.size.1 as f32;
        self.live.set_camera(self.orbit.camera(aspect));
        let paused = self.paused && !std::mem::take(&mut self.step_once);
        let stepped = match self.live.unstable.take() {
            Some(m) => Err(Error::Unstable(m)),
            None => self.live.step(ctx, paused, false),
        };
        match stepped {
            // Shown, not fatal: the picture stays, paused, for a reset or other switches.
            Err(Error::Unstable(m)) => {
                self.paused = true;
                self.message = format!("unstable, paused (R resets): {m}");
                eprintln!("view: {}", self.message);
                Ok(())
            }
            r => r,
        }
    }

    /// Carry out `cmd`; a command that cannot be done leaves the scene as it was and says
    /// why in the panel (and on stderr). Only device failures are errors.
    pub fn apply(
        &mut self,
        ctx: &Context,
        cmd: Command,
        window: Option<&winit::window::Window>,
    ) -> Result<()> {
        let said = match cmd {
            Command::Set(name, value) => self.flip(ctx, &name, Some(&value)),
            Command::Unset(name) => self.flip(ctx, &name, None),
            Command::Cycle(name) => {
                let all = flags::all();
                let values = all
                    .iter()
                    .find(|f| f.name == name)
                    .map(|f| f.values.clone());
                let values = values.unwrap_or_default();
                let now = flags::value_in(&self.live.sw, &name);
                let i = values.iter().position(|v| Some(v) == now.as_ref());
                match values.get(i.map_or(0, |i| (i + 1) % values.len())) {
                    Some(next) => self.flip(ctx, &name, Some(&next.clone())),
                    None => Ok(format!("--{name} has no list of values")),
                }
            }
            Command::Pause => Ok(self.pause(true)),
            Command::Resume => Ok(self.pause(false)),
            Command::TogglePause => Ok(self.pause(!self.paused)),
            Command::Step => {
                (self.paused, self.step_once) = (true, true);
                Ok("one frame's simulation".into())
            }
            Command::Reset => self
                .rebuild(ctx, self.args.clone())
                .map(|_| "scene reset".into()),
            Command::Speed(s) => Ok(self.set_speed(s)),
            Command::SpeedTimes(k) => Ok(self.set_speed(self.speed * k)),
            Command::Seek(t) => self.seek(ctx, t),
            Command::Screenshot(path, size) => self.screenshot(ctx, &path, size),
            Command::Record(dir) => self.record(&dir),
            Command::RecordStop => self.record_stop(),
            Command::CameraHome => {
                self.orbit.reset();
                Ok("camera home".into())
            }
            Command::CameraFly(on) => {
                self.orbit.fly = on;
                Ok(format!("fly mode {}", if on { "on" } else { "off" }))
            }
            Command::Resize(w, h) => {
                if let Some(win) = window {
                    let _ = win.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                }
                Ok(format!("asked the window for {w}x{h}"))
            }
            Command::Minimize(on) => {
                if let Some(w) = window {
                    w.set_minimized(on);
                }
                Ok(if on { "minimised" } else { "restored" }.into())
            }
            Command::Copy => {
                let line = flags::command_line(&self.scene, &self.args);
                println!("{line}");
                // X11 serves the selection while the clipboard lives: it stays open.
                if self.clipboard.is_none() {
                    self.clipboard = arboard::Clipboard::new().ok();
                }
                let copied = self.clipboard.as_mut().map(|c| c.set_text(line.clone()));
                Ok(match copied {
                    Some(Ok(())) => format!("copied: {line}"),
                    _ => format!("printed (no clipboard): {line}"),
                })
            }
            Command::TogglePanel => Ok(String::new()),
            Command::Quit => {
                self.quit = true;
                Ok(String::new())
            }
        };
        match said {
            Ok(m) => {
                if !m.is_empty() && !self.live.sw.common.quiet {
                    eprintln!("view: frame {}: {m}", self.live.frame);
                }
                self.message = m;
            }
            Err(e @ (Error::Vulkan { .. } | Error::Memory(_))) => return Err(e),
            Err(e) => {
                self.message = format!("error: {e}");
                eprintln!("view: {e}");
            }
        }
        Ok(())
    }

    fn set_speed(&mut self, s: f64) -> String {
        self.speed = s.clamp(0.125, 8.0);
        self.live.set_speed(self.speed);
        format!("speed x{}", self.speed)
    }

    /// The window's inner size changed: the view follows it (the simulation goes on).
    pub fn resize(&mut self, ctx: &Context, size: (u32, u32)) -> Result<()> {
        if size.0 == 0 || size.1 == 0 || size == self.size {
            return Ok(());
        }
        self.size = size;
        let sw = flags::parse(&self.args).map_err(Error::Param)?;
        self.live.rebuild_view(ctx, &sized(&sw, size)).map(|_| ())
    }

    fn pause(&mut self, on: bool) -> String {
        self.paused = on;
        if on { "paused" } else { "playing" }.into()
    }

    /// Set (or unset) `--name`: the view rebuilt for picture switches, else the scene.
    fn flip(&mut self, ctx: &Context, name: &str, value: Option<&str>) -> Result<String> {
        let group = flags::group_of(name);
        if group.is_empty() {
            return Err(Error::Param(format!("--{name} is not a switch of run")));
        }
        if matches!(group.as_str(), "FrameArgs" | "ExportArgs") || name == "device" {
            return Err(Error::Param(format!(
                "--{name} cannot change in the viewer"
            )));
        }
        let args = flags::with(&self.args, name, value);
        let sw = flags::parse(&args).map_err(Error::Param)?;
        let shown = value.unwrap_or("(default)");
        if flags::view_only(&group) {
            let home = self.live.rebuild_view(ctx, &sized(&sw, self.size))?;
            if group == "CameraArgs" {
                self.orbit = Orbit::new(home);
            }
            self.args = args;
            return Ok(format!(
                "--{name} {shown}: view rebuilt, simulation goes on"
            ));
        }
        if group == "ControlArgs" && self.live.set_control(&sw)? {
            self.args = args;
            return Ok(format!(
                "--{name} {shown}: control changed, simulation goes on"
            ));
        }
        self.rebuild(ctx, args)?;
        Ok(format!(
            "--{name} {shown}: the scene was rebuilt (its simulation restarted)"
        ))
    }

    /// The scene made anew from `args` (kept only if it opens).
    fn rebuild(&mut self, ctx: &Context, args: Vec<String>) -> Result<()> {
        let sw = flags::parse(&args).map_err(Error::Param)?;
        self.live.settle(ctx)?;
        let live = LiveScene::open(ctx, &self.scene, &sized(&sw, self.size))?;
        let mut old = std::mem::replace(&mut self.live, live);
        old.destroy(ctx);
        self.live.set_speed(self.speed);
        self.args = args;
        Ok(())
    }

    /// Jump to scene time `t`: from the start, re-simulated without pictures.
    fn seek(&mut self, ctx: &Context, t: f64) -> Result<String> {
        self.rebuild(ctx, self.args.clone())?;
        while self.live.sim_time() + 1e-9 < t {
            self.live.step(ctx, false, true)?;
        }
        self.live.step(ctx, true, false)?;
        self.paused = true;
        Ok(format!(
            "at t = {:.3} s (re-simulated from 0, paused)",
            self.live.sim_time()
        ))
    }

    /// The newest picture as a PNG at `path` ("": the next free view_NNNN.png), at the
    /// window's size or redrawn at `size`.
    fn screenshot(
        &mut self,
        ctx: &Context,
        path: &Path,
        size: Option<(u32, u32)>,
    ) -> Result<String> {
        let path = match path.as_os_str().is_empty() {
            true => free_name("view_", ".png"),
            false => path.to_path_buf(),
        };
        let sw = flags::parse(&self.args).map_err(Error::Param)?;
        if let Some(s) = size {
            self.live.rebuild_view(ctx, &sized(&sw, s))?;
            self.live.step(ctx, true, false)?;
        }
        self.live.settle(ctx)?;
        let saved = match self.live.picture() {
            Some((rgba, w, h)) => crate::gpu::target::save_rgba(&path, w, h, rgba).map(|_| (w, h)),
            None => Err(Error::Param(match &self.live.unstable {
                Some(m) => format!("no picture: the simulation went unstable: {m}"),
                None => "no picture yet".into(),
            })),
        };
        if size.is_some() {
            self.live.rebuild_view(ctx, &sized(&sw, self.size))?;
        }
        let (w, h) = saved?;
        Ok(format!("saved {} ({w}x{h})", path.display()))
    }

    fn record(&mut self, dir: &Path) -> Result<String> {
        let dir = match dir.as_os_str().is_empty() {
            true => PathBuf::from("view_recording"),
            false => dir.to_path_buf(),
        };
        if self.recording.is_some() {
            return self.record_stop();
        }
        std::fs::create_dir_all(&dir).map_err(|e| Error::Io {
            path: dir.display().to_string(),
            source: e,
        })?;
        self.recording = Some((dir.clone(), 0));
        Ok(format!("recording to {}", dir.display()))
    }

    /// After a presented frame: its picture to the recording, if one is on.
    pub fn record_frame(&mut self) -> Result<()> {
        let (Some((dir, n)), Some((rgba, w, h))) = (&mut self.recording, self.live.picture())
        else {
            return Ok(());
        };
        let path = dir.join(format!("frame_{n:04}.png"));
        crate::gpu::target::save_rgba(&path, w, h, rgba)?;
        *n += 1;
        Ok(())
    }

    /// Stop recording: its frames (those of the first frame's size) as animation.png.
    fn record_stop(&mut self) -> Result<String> {
        let Some((dir, n)) = self.recording.take() else {
            return Ok("not recording".into());
        };
        let frames: Vec<_> = (0..n)
            .filter_map(|i| image::open(dir.join(format!("frame_{i:04}.png"))).ok())
            .map(|im| im.to_rgba8())
            .collect();
        let Some(first) = frames.first() else {
            return Ok("recording stopped: no frames".into());
        };
        let (w, h) = first.dimensions();
        let same: Vec<_> = frames.iter().filter(|f| f.dimensions() == (w, h)).collect();
        let path = dir.join("animation.png");
        let fps = crate::run::ANIMATION_FPS;
        let mut a = crate::animation::Animation::create(&path, w, h, same.len() as u32, fps)?;
        for f in &same {
            a.add(f.as_raw(), w, h)?;
        }
        a.finish()?;
        Ok(format!("wrote {} frames and {}", n, path.display()))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let _ = self.record_stop();
        self.live.destroy(ctx);
    }
}

/// The first `prefixNNNN suffix` that does not exist yet.
fn free_name(prefix: &str, suffix: &str) -> PathBuf {
    (0..)
        .map(|i| PathBuf::from(format!("{prefix}{i:04}{suffix}")))
        .find(|p| !p.exists())
        .expect("a free file name")
}
