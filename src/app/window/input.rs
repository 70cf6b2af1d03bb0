//! The window and its events (winit, pumped once per frame): keys become commands,
//! mouse drags and the wheel move the camera, the rest goes to the overlay (egui).
use super::command::Command;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Camera motion gathered since the last frame.
#[derive(Default)]
pub struct Motion {
    pub rotate: (f32, f32),
    pub pan: (f32, f32),
    pub zoom: f32,
}

pub struct Input {
    pub window: Option<Window>,
    pub egui: Option<egui_winit::State>,
    pub egui_ctx: egui::Context,
    size: (u32, u32),
    pub commands: Vec<Command>,
    pub motion: Motion,
    /// The inner size changed (the swapchain and the view follow).
    pub resized: Option<(u32, u32)>,
    pub close: bool,
    pub error: Option<String>,
    buttons: (bool, bool),
    cursor: Option<(f64, f64)>,
    held: std::collections::HashSet<char>,
}

impl Input {
    pub fn new(size: (u32, u32)) -> Self {
        Self {
            window: None,
            egui: None,
            egui_ctx: egui::Context::default(),
            size,
            commands: Vec::new(),
            motion: Motion::default(),
            resized: None,
            close: false,
            error: None,
            buttons: (false, false),
            cursor: None,
            held: Default::default(),
        }
    }

    /// The fly keys held now, as (right, up, forward).
    pub fn walk(&self) -> [f32; 3] {
        let k = |c: char| self.held.contains(&c) as i32 as f32;
        [k('d') - k('a'), k('e') - k('c'), k('w') - k('s')]
    }

    fn key(&mut self, key: &Key) {
        let c = match key {
            Key::Named(NamedKey::Space) => Some(Command::TogglePause),
            Key::Named(NamedKey::Escape) => Some(Command::Quit),
            Key::Named(NamedKey::Tab) => Some(Command::TogglePanel),
            Key::Named(NamedKey::Home) => Some(Command::CameraHome),
            Key::Character(s) => match s.to_lowercase().as_str() {
                "n" => Some(Command::Step),
                "r" => Some(Command::Reset),
                "+" | "=" => Some(Command::SpeedTimes(2.0)),
                "-" => Some(Command::SpeedTimes(0.5)),
                "l" => Some(Command::Cycle("list".into())),
                "b" => Some(Command::Cycle("density".into())),
                "m" => Some(Command::Cycle("material".into())),
                "h" => Some(Command::CameraHome),
                "f" => Some(Command::CameraFly(true)),
                "p" => Some(Command::Screenshot("".into(), None)),
                "v" => Some(Command::Record("".into())),
                "q" => Some(Command::Quit),
                _ => None,
            },
            _ => None,
        };
        self.commands.extend(c);
    }
}

impl ApplicationHandler for Input {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attrs = Window::default_attributes()
            .with_title("fluidform view")
            .with_inner_size(winit::dpi::PhysicalSize::new(self.size.0, self.size.1));
        match el.create_window(attrs) {
            Ok(w) => {
                let id = self.egui_ctx.viewport_id();
                let scale = Some(w.scale_factor() as f32);
                let st = egui_winit::State::new(self.egui_ctx.clone(), id, &w, scale, None, None);
                self.egui = Some(st);
                self.window = Some(w);
            }
            Err(e) => self.error = Some(format!("cannot open a window: {e}")),
        }
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let (Some(w), Some(st)) = (&self.window, &mut self.egui) else {
            return;
        };
        let used = st.on_window_event(w, &event).consumed;
        match event {
            WindowEvent::CloseRequested => self.close = true,
            WindowEvent::Resized(s) => self.resized = Some((s.width, s.height)),
            WindowEvent::KeyboardInput { event, .. } if !used => {
                let down = event.state == ElementState::Pressed;
                if let Key::Character(s) = &event.logical_key {
                    let c = s.to_lowercase().chars().next().unwrap_or(' ');
                    // Fly keys move while held; elsewhere they do nothing.
                    if "wasdec".contains(c) {
                        match down {
                            true => self.held.insert(c),
                            false => self.held.remove(&c),
                        };
                        return;
                    }
                }
                if down && !event.repeat {
                    self.key(&event.logical_key);
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed && !used;
                match button {
                    MouseButton::Left => self.buttons.0 = down,
                    MouseButton::Right | MouseButton::Middle => self.buttons.1 = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x, position.y);
                if let Some(c) = self.cursor {
                    let d = ((p.0 - c.0) as f32, (p.1 - c.1) as f32);
                    if self.buttons.0 {
                        self.motion.rotate.0 += d.0;
                        self.motion.rotate.1 += d.1;
                    } else if self.buttons.1 {
                        self.motion.pan.0 += d.0;
                        self.motion.pan.1 += d.1;
                    }
                }
                self.cursor = Some(p);
            }
            WindowEvent::MouseWheel { delta, .. } if !used => {
                self.motion.zoom += match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
            }
            _ => {}
        }
    }
}
