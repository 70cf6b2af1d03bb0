//! The overlay panel (egui): scene numbers, per-pass GPU timings as a table and a stacked
//! plot, playback and the timeline, camera, pictures, and every switch of `run` by its
//! flag. Controls only emit commands; the session carries them out.
use super::command::{Command, KEYS};
use super::flags::{self, Flag};
use crate::gpu::FrameTiming;
use crate::run::live::LiveStats;
use std::collections::BTreeMap;

/// What the panel remembers between frames.
pub struct PanelState {
    pub shown: bool,
    /// Text being typed per flag, until Enter.
    edits: BTreeMap<String, String>,
    shot_size: (u32, u32),
    seek: f64,
}

impl Default for PanelState {
    fn default() -> Self {
        Self {
            shown: true,
            edits: BTreeMap::new(),
            shot_size: (1920, 1080),
            seek: 0.0,
        }
    }
}

/// What the panel shows this frame.
pub struct PanelView<'a> {
    pub scene: &'a str,
    pub frame: u64,
    pub paused: bool,
    pub speed: f64,
    pub recording: bool,
    pub fly: bool,
    /// Milliseconds between window frames (wall clock).
    pub wall_ms: f64,
    pub stats: &'a LiveStats,
    pub timings: &'a [FrameTiming],
    pub events: &'a [(f32, String)],
    pub flags: &'a [Flag],
    /// The switches as the scene applied them (serialised once a frame), and the flags
    /// the user set.
    pub sw: &'a serde_json::Value,
    pub args: &'a [String],
    pub message: &'a str,
}

/// Per-frame sums of the top-level passes (each step repeats them).
fn top_passes(t: &FrameTiming) -> BTreeMap<&str, f64> {
    let mut m = BTreeMap::new();
    for (name, ms) in &t.passes {
        if !name.contains('/') && name != "frame" {
            *m.entry(name.as_str()).or_default() += ms;
        }
    }
    m
}

const COLORS: [egui::Color32; 8] = [
    egui::Color32::from_rgb(86, 156, 214),
    egui::Color32::from_rgb(220, 140, 60),
    egui::Color32::from_rgb(120, 200, 120),
    egui::Color32::from_rgb(200, 90, 90),
    egui::Color32::from_rgb(170, 130, 220),
    egui::Color32::from_rgb(200, 200, 90),
    egui::Color32::from_rgb(90, 200, 200),
    egui::Color32::from_rgb(160, 160, 160),
];

pub fn ui(ctx: &egui::Context, st: &mut PanelState, v: &PanelView, out: &mut Vec<Command>) {
    if !st.shown {
        return;
    }
    egui::SidePanel::left("fluidform")
        .default_width(340.0)
        .show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                numbers(ui, v);
                timings(ui, v);
                playback(ui, st, v, out);
                pictures(ui, st, v, out);
                switches(ui, st, v, out);
                ui.collapsing("Keys", |ui| {
                    for (k, what) in KEYS {
                        ui.label(format!("{k}: {what}"));
                    }
                });
            });
        });
}

fn numbers(ui: &mut egui::Ui, v: &PanelView) {
    let s = v.stats;
    ui.heading(format!("fluidform view: {}", v.scene));
    let gpu = v.timings.last().map(|t| t.frame_ms).unwrap_or(f64::NAN);
    ui.label(format!(
        "frame {}  t = {:.3} s  steps {}{}",
        v.frame,
        s.sim_time,
        s.steps,
        if v.paused { "  (paused)" } else { "" }
    ));
    ui.label(format!(
        "{:.1} ms/frame ({:.1} fps)  GPU frame {gpu:.2} ms",
        v.wall_ms,
        1000.0 / v.wall_ms.max(1e-3)
    ));
    let r = &s.render;
    let frags = r.last_frame.as_ref().map(|f| f.fragments).unwrap_or(0);
    ui.label(format!(
        "{} particles  {} list fragments  {:.1} MiB",
        s.particles,
        frags,
        s.memory_bytes as f64 / (1 << 20) as f64
    ));
    for row in &s.control {
        ui.label(format!(
            "control {}: fill {:.3}  iou {:.3}  spray {:.3}",
            row.target, row.fill, row.iou, row.spray
        ));
    }
}

fn timings(ui: &mut egui::Ui, v: &PanelView) {
    let head = egui::CollapsingHeader::new("GPU timings (ms, mean of the last 30 frames)");
    head.default_open(true).show(ui, |ui| {
        let last: Vec<&FrameTiming> = v.timings.iter().rev().take(30).collect();
        let mut sums: BTreeMap<String, f64> = BTreeMap::new();
        for t in &last {
            for (name, ms) in &t.passes {
                if name.matches('/').count() <= 1 {
                    *sums.entry(name.clone()).or_default() += ms;
                }
            }
        }
        let n = last.len().max(1) as f64;
        egui::Grid::new("passes").striped(true).show(ui, |ui| {
            for (name, total) in &sums {
                ui.label(name);
                ui.label(format!("{:9.3}", total / n));
                ui.end_row();
            }
        });
        // Stacked bars of the top-level passes over the last frames.
        let recent: Vec<_> = v.timings.iter().rev().take(120).rev().collect();
        let names: Vec<String> = {
            let mut s: Vec<String> = recent
                .iter()
                .flat_map(|t| top_passes(t).into_keys().map(String::from))
                .collect();
            s.sort();
            s.dedup();
            s
        };
        let peak = recent.iter().map(|t| t.frame_ms).fold(1e-6, f64::max);
        let (rect, _) = ui.allocate_exact_size(egui::vec2(300.0, 90.0), egui::Sense::hover());
        let p = ui.painter_at(rect);
        p.rect_filled(rect, 2.0, egui::Color32::from_gray(20));
        let w = rect.width() / 120.0;
        for (i, t) in recent.iter().enumerate() {
            let x = rect.left() + i as f32 * w;
            let mut y = rect.bottom();
            for (name, ms) in top_passes(t) {
                let k = names.iter().position(|n| n == name).unwrap_or(0);
                let h = (ms / peak) as f32 * rect.height();
                let r = egui::Rect::from_min_max(egui::pos2(x, y - h), egui::pos2(x + w, y));
                p.rect_filled(r, 0.0, COLORS[k % COLORS.len()]);
                y -= h;
            }
        }
        ui.horizontal_wrapped(|ui| {
            for (k, n) in names.iter().enumerate() {
                ui.colored_label(COLORS[k % COLORS.len()], n);
            }
            ui.label(format!("(top {peak:.2} ms)"));
        });
    });
}

fn playback(ui: &mut egui::Ui, st: &mut PanelState, v: &PanelView, out: &mut Vec<Command>) {
    ui.separator();
    ui.horizontal(|ui| {
        let label = if v.paused { "Resume" } else { "Pause" };
        if ui.button(label).clicked() {
            out.push(Command::TogglePause);
        }
        if ui.button("Step").clicked() {
            out.push(Command::Step);
        }
        if ui.button("Reset").clicked() {
            out.push(Command::Reset);
        }
    });
    let mut speed = v.speed;
    let slider = egui::Slider::new(&mut speed, 0.125..=8.0)
        .logarithmic(true)
        .text("speed");
    if ui.add(slider).changed() {
        out.push(Command::Speed(speed));
    }
    let end = (v.events.iter().map(|e| e.0 as f64))
        .fold(v.stats.sim_time, f64::max)
        .max(1.0);
    let r = ui.add(egui::Slider::new(&mut st.seek, 0.0..=end).text("seek (s)"));
    if r.drag_stopped() || (r.changed() && !r.dragged()) {
        out.push(Command::Seek(st.seek));
    }
    if !r.dragged() {
        st.seek = v.stats.sim_time;
    }
    for (t, what) in v.events {
        let done = (*t as f64) <= v.stats.sim_time;
        ui.label(format!(
            "{} {t:6.2} s  {what}",
            if done { "✔" } else { "·" }
        ));
    }
    ui.horizontal(|ui| {
        if ui.button("Camera home").clicked() {
            out.push(Command::CameraHome);
        }
        let mut fly = v.fly;
        if ui.checkbox(&mut fly, "fly (W A S D E C)").changed() {
            out.push(Command::CameraFly(fly));
        }
    });
}

fn pictures(ui: &mut egui::Ui, st: &mut PanelState, v: &PanelView, out: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        if ui.button("Screenshot").clicked() {
            out.push(Command::Screenshot("".into(), None));
        }
        ui.add(egui::DragValue::new(&mut st.shot_size.0).range(1..=16384));
        ui.label("x");
        ui.add(egui::DragValue::new(&mut st.shot_size.1).range(1..=16384));
        if ui.button("at size").clicked() {
            out.push(Command::Screenshot("".into(), Some(st.shot_size)));
        }
    });
    let label = if v.recording {
        "Stop recording"
    } else {
        "Record"
    };
    if ui.button(label).clicked() {
        out.push(match v.recording {
            true => Command::RecordStop,
            false => Command::Record("".into()),
        });
    }
    if !v.message.is_empty() {
        ui.colored_label(egui::Color32::from_rgb(240, 200, 120), v.message);
    }
}

fn switches(ui: &mut egui::Ui, st: &mut PanelState, v: &PanelView, out: &mut Vec<Command>) {
    ui.separator();
    let line = flags::command_line(v.scene, v.args);
    if ui.button("Copy the run command line").clicked() {
        out.push(Command::Copy);
    }
    ui.label(egui::RichText::new(line).monospace().small());
    let mut groups: Vec<&str> = v.flags.iter().map(|f| f.group.as_str()).collect();
    groups.dedup();
    for g in groups {
        if matches!(g, "CommonArgs" | "FrameArgs" | "ExportArgs") {
            continue;
        }
        let how = match g {
            g if flags::view_only(g) => "live",
            "ControlArgs" => "c_cp, thresholds, factors, velocity, attraction, damping live",
            _ => "rebuilds the scene",
        };
        let title = format!("{} ({how})", g.trim_end_matches("Args"));
        ui.collapsing(title, |ui| {
            for f in v.flags.iter().filter(|f| f.group == g) {
                flag_row(ui, st, v, f, out);
            }
        });
    }
    ui.collapsing("Common (rebuilds the scene)", |ui| {
        for f in v
            .flags
            .iter()
            .filter(|f| f.name == "particles" || f.name == "seed")
        {
            flag_row(ui, st, v, f, out);
        }
    });
}

fn flag_row(
    ui: &mut egui::Ui,
    st: &mut PanelState,
    v: &PanelView,
    f: &Flag,
    out: &mut Vec<Command>,
) {
    let now = flags::value_at(v.sw, &f.name);
    ui.horizontal(|ui| {
        ui.label(format!("--{}", f.name)).on_hover_text(&f.help);
        let shown = now.clone().unwrap_or_else(|| "(default)".into());
        if f.boolean {
            let mut on = now.as_deref() == Some("true");
            if ui.checkbox(&mut on, "").changed() {
                out.push(Command::Set(f.name.clone(), on.to_string()));
            }
        } else if !f.values.is_empty() {
            egui::ComboBox::from_id_salt(&f.name)
                .selected_text(shown)
                .show_ui(ui, |ui| {
                    if ui.selectable_label(now.is_none(), "(default)").clicked() {
                        out.push(Command::Unset(f.name.clone()));
                    }
                    for val in &f.values {
                        let on = now.as_deref() == Some(val.as_str());
                        if ui.selectable_label(on, val).clicked() && !on {
                            out.push(Command::Set(f.name.clone(), val.clone()));
                        }
                    }
                });
        } else {
            let text = st
                .edits
                .entry(f.name.clone())
                .or_insert_with(|| now.clone().unwrap_or_default());
            let r = ui.add(
                egui::TextEdit::singleline(text)
                    .desired_width(110.0)
                    .hint_text(shown),
            );
            if r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                out.push(match text.trim() {
                    "" => Command::Unset(f.name.clone()),
                    t => Command::Set(f.name.clone(), t.to_string()),
                });
            }
            if !r.has_focus() && !r.lost_focus() {
                *text = now.unwrap_or_default();
            }
        }
    });
}
