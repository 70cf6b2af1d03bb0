//! A scene's characters and control targets as it plays: the `[character]` (with its
//! `[control]`, the target "character") and the `[[targets]]`, attached, switched, united
//! and released by the timeline; each attached target's pose set before the frame's
//! steps, its metrics read after them; the first shown mesh drawn by the view.
use crate::character::capsules::{self, BoneCapsule};
use crate::control::fits::{Plays, DIP};
use crate::control::metrics::{ControlMetrics, ControlStats};
use crate::control::target::{ControlDesc, ControlTarget};
use crate::control::timeline::{FiredEvent, Timeline};
use crate::control::ControlMotion;
use crate::emission::emitter::{EmitSource, Emitter};
use crate::emission::layout::UvLayout;
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Context, Guard, Profiler};
use crate::render::mesh::MeshDraw;
use crate::render::ShowMesh;
use crate::scene::around::played_times;
use crate::scene::character::{placed_rest_bounds, CharacterDesc};
use crate::scene::schema::MAIN_TARGET;
use crate::scene::Scene;
use crate::settings::TargetOptions;
use crate::sph::hooks::Hooks;
use crate::sph::params::{Collider, GpuCollider, MAX_COLLIDERS};
use crate::sph::{SphSolver, SphState};
use character::{CharacterStats, SceneCharacter};
use emission::{EmissionMetrics, EmissionStats, SceneEmission};
use glam::Mat4;
use serde::{Deserialize, Serialize};

const CONTROL_METRICS_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("control-metrics");
const EMISSION_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("emission");

pub mod character;
pub mod emission;
mod viewer;

/// `stats.control` of summary.json: each control target's metrics and the fired events.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ControlSummary {
    pub targets: Vec<ControlStats>,
    pub events: Vec<FiredEvent>,
}

/// A frame's placed joint matrices, those a moment before, and the scene time.
/// The frame's joint matrices and morph weights, those a moment before, and its time.
type FramePose = ((Vec<Mat4>, Vec<f32>), (Vec<Mat4>, Vec<f32>), f64);

struct Live {
    name: String,
    character: SceneCharacter,
    control: Option<(ControlTarget, ControlMetrics)>,
    /// The scene's own control description, before the switches (the viewer's flips).
    desc: Option<ControlDesc>,
    /// Per slot: the placed joint matrices of the frame and of a moment before it (the
    /// skin's speed), and the scene time, when attached.
    poses: Vec<Option<FramePose>>,
    /// The character, shared with the metrics' worker threads (which skin it).
    shared: std::sync::Arc<crate::character::Character>,
}

/// The skin's speed is its motion over this many seconds before the frame.
const SKIN_SPEED_DT: f64 = 1.0 / 240.0;

pub struct SceneTargets {
    live: Vec<Live>,
    /// The character's emission, if the scene has one.
    emission: Option<SceneEmission>,
    /// The scene's own colliders (the emitting character's capsules join them per frame).
    colliders: Vec<GpuCollider>,
    /// The emitting character's capsules, when they collide.
    capsules: Vec<BoneCapsule>,
    /// Index into `live` of each control target (timeline order of names).
    controlled: Vec<usize>,
    timeline: Timeline,
    pub fired: Vec<FiredEvent>,
    /// Per control target being let go: (start time, strength then, fade seconds).
    fading: Vec<Option<(f64, f32, f32)>>,
    quiet: bool,
    /// The floor's height (the domain's bottom) and the metrics window's start.
    floor: f32,
    metrics_from: Option<f64>,
}

impl SceneTargets {
    /// Load, place and bind every character and target of `scene` (errors before the
    /// first frame); each control target searches the fluid the way `solver` does. Long
    /// because each character and target is made under the guard of the whole.
    pub fn new(
        ctx: &Context,
        scene: &Scene,
        opts: &TargetOptions,
        solver: &SphSolver,
        st: &mut SphState,
        initial: &[[f32; 4]],
        slots: usize,
    ) -> Result<Self> {
        let method = opts.skinning;
        let mut descs: Vec<(String, &CharacterDesc, Option<&ControlDesc>)> = Vec::new();
        if let Some(c) = &scene.character {
            descs.push((MAIN_TARGET.into(), c, scene.control.as_ref()));
        }
        for t in &scene.targets {
            descs.push((t.name.clone(), &t.character, Some(&t.control)));
        }
        let mut out = Guard::new(
            ctx,
            Self {
                live: Vec::new(),
                emission: None,
                colliders: scene
                    .colliders
                    .iter()
                    .map(|c| c.to_gpu())
                    .collect::<Result<_>>()?,
                capsules: Vec::new(),
                controlled: Vec::new(),
                timeline: Timeline::default(),
                fired: Vec::new(),
                fading: Vec::new(),
                quiet: opts.quiet,
                floor: scene.domain.min[1],
                metrics_from: opts.metrics_from,
            },
        );
        for (name, cdesc, control) in descs {
            // A liquid character hides its mesh unless asked.
            let show = opts.show_mesh.unwrap_or(match control {
                Some(_) => ShowMesh::Off,
                None => ShowMesh::Shaded,
            });
            let character = Guard::new(ctx, SceneCharacter::new(ctx, cdesc, method, show)?);
            let scene_desc = control.cloned();
            let control = match control {
                Some(d) => {
                    // What must fit: the poses that play, by the fitted domain's rule.
                    let times = played_times(scene, cdesc, &character.ch, &character.anim);
                    let poses: Vec<_> = times
                        .iter()
                        .map(|&t| (t, character.matrices(t), character.morph_weights(t)))
                        .collect();
                    let (lo, hi) = placed_rest_bounds(&character.ch, &character.anim)?;
                    let plays = Plays {
                        domain: (scene.domain.min, scene.domain.max),
                        slack: DIP * (hi.y - lo.y),
                        poses: &poses,
                        frame_s: scene.fluid.dt as f64 * scene.fluid.substeps as f64,
                    };
                    let t = ControlTarget::new(
                        ctx,
                        solver,
                        &character.ch,
                        &character.anim,
                        &(opts.control)(d)?,
                        &scene.fluid,
                        &plays,
                        (opts.seed, method),
                    )?;
                    let m = ControlMetrics::new(ctx, st.n, t.count(), &name, slots)?;
                    let i = out.live.len();
                    out.controlled.push(i);
                    Some((t, m))
                }
                None => None,
            };
            let character = character.take();
            out.live.push(Live {
                desc: scene_desc,
                name,
                shared: std::sync::Arc::new(character.ch.clone()),
                character,
                control,
                poses: vec![None; slots],
            });
        }
        let names = scene.control_targets();
        out.timeline = match scene.timeline.is_empty() {
            true => Timeline::all_attached(&names),
            false => Timeline::new(&scene.name, &scene.timeline, &names)?,
        };
        if let Some(desc) = &scene.emission {
            out.add_emission(ctx, scene, desc, opts, st, initial, slots)?;
        }
        let mut t = out.take();
        t.fading = vec![None; t.controlled.len()];
        for (k, &i) in t.controlled.iter().enumerate() {
            let (c, _) = t.live[i].control.as_mut().expect("a control target");
            c.force
                .set_attached(t.timeline.attached(k), t.timeline.strength(k));
        }
        Ok(t)
    }

    /// The scene's emitter on its first character, with the character's capsules as
    /// colliders when it collides.
    #[allow(clippy::too_many_arguments)]
    fn add_emission(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        desc: &crate::scene::emission::EmissionDesc,
        opts: &TargetOptions,
        st: &mut SphState,
        initial: &[[f32; 4]],
        slots: usize,
    ) -> Result<()> {
        // validate() made sure of the [character]: the first character.
        let (kind, settings, size) = desc.resolve(&opts.emission)?;
        let ch = &self.live[0].character.ch;
        let caps = capsules::of(ch);
        if desc.collide && caps.len() + self.colliders.len() > MAX_COLLIDERS {
            return Err(crate::Error::Param(format!(
                "scene {}: {} character capsules and {} colliders exceed {MAX_COLLIDERS}",
                scene.name,
                caps.len(),
                self.colliders.len()
            )));
        }
        let layout = match kind {
            crate::emission::EmitterKind::Vertices => None,
            _ if !ch.mesh.uvs.is_empty() => Some(UvLayout::from_mesh(&ch.mesh, size)?),
            _ => Some(UvLayout::from_capsules(&ch.mesh, &caps, size)?),
        };
        let metrics = Guard::new(ctx, EmissionMetrics::new(ctx, slots)?);
        let source = EmitSource::new(ctx, kind, layout, &ch.mesh.positions, size)?;
        let emitter = Emitter::new(
            ctx,
            st,
            initial,
            source,
            (settings, desc.recycle),
            opts.seed,
        )?;
        if desc.collide {
            self.capsules = caps;
        }
        self.emission = Some(SceneEmission {
            emitter,
            metrics: metrics.take(),
            character: 0,
            slots: desc.slots,
            primed: false,
        });
        Ok(())
    }

    pub fn is_empty(&self) -> bool {
        self.live.is_empty()
    }

    /// Before the frame's steps: fire the events due at scene time `t` and set every
    /// attached target's pose (`frame_dt` after the previous one).
    pub fn record_poses(&mut self, frame: u64, t: f64, frame_dt: f32, slot: usize) -> Result<()> {
        for (event, changes) in self.timeline.due(t) {
            if !self.quiet {
                eprintln!("t = {t:.3} s (frame {frame}): {}", event.describe());
            }
            for (k, attached, strength) in changes {
                let (c, _) = self.live[self.controlled[k]]
                    .control
                    .as_mut()
                    .expect("control");
                match attached {
                    true => {
                        self.fading[k] = None;
                        c.force.set_attached(true, strength);
                    }
                    // Let go over the fade (at once when it is 0).
                    false if c.force.attached() => {
                        self.fading[k] = Some((t, strength, event.fade()));
                    }
                    false => {}
                }
            }
            self.fired.push(FiredEvent {
                frame,
                time: t,
                event,
            });
        }
        for (k, f) in self.fading.iter_mut().enumerate() {
            let Some((t0, s0, d)) = *f else { continue };
            let (c, _) = self.live[self.controlled[k]]
                .control
                .as_mut()
                .expect("control");
            let left = match d > 0.0 {
                true => 1.0 - (t - t0) as f32 / d,
                false => 0.0,
            };
            if left <= 0.0 {
                c.force.set_attached(false, s0);
                *f = None;
            } else {
                c.force.set_attached(true, s0 * left);
            }
        }
        for l in &mut self.live {
            l.poses[slot] = None;
            let Some((c, _)) = l.control.as_mut().filter(|(c, _)| c.force.attached()) else {
                continue;
            };
            let ch = &l.character;
            let (mats, weights) = (ch.matrices(t), ch.morph_weights(t));
            let ahead = t + frame_dt as f64;
            let next = (c.force.settings.motion == ControlMotion::Skin)
                .then(|| (ch.matrices(ahead), ch.morph_weights(ahead)));
            let next = next.as_ref().map(|(m, w)| (&m[..], &w[..]));
            c.set_pose(&ch.ch, (&mats, &weights), next, frame_dt)?;
            // (Ahead of the clip's start rather than across a loop's seam into its end.)
            let moment = match t >= SKIN_SPEED_DT {
                true => t - SKIN_SPEED_DT,
                false => t + SKIN_SPEED_DT,
            };
            let before = (ch.matrices(moment), ch.morph_weights(moment));
            l.poses[slot] = Some(((mats, weights), before, t));
        }
        Ok(())
    }

    /// Before the frame's `steps` steps from scene time `t` over `frame_dt`: the emitting
    /// character skinned to the frame's end and taken by the emission source (on the
    /// first frame its start too), and its capsules posed as colliders.
    #[allow(clippy::too_many_arguments)]
    pub fn record_before(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        st: &mut SphState,
        t: f64,
        frame_dt: f32,
        steps: u32,
    ) -> Result<()> {
        let Some(e) = &mut self.emission else {
            return Ok(());
        };
        let ch = &self.live[e.character].character;
        let end = t + frame_dt as f64;
        let emitter = &mut e.emitter;
        {
            let mut prof = prof.open(ctx, cmd, EMISSION_SCOPE);
            let times: &[f64] = match e.primed {
                true => &[end],
                false => &[t, end],
            };
            for &at in times {
                ch.record(ctx, cmd, &mut *prof, at)?;
                emitter.source.record(ctx, cmd, &mut *prof, ch.skinned())?;
            }
        }
        e.primed = true;
        emitter.begin_frame(steps, frame_dt);
        if !self.capsules.is_empty() {
            let (m0, m1) = (ch.matrices(t), ch.matrices(end));
            let mut list = self.colliders.clone();
            for c in &self.capsules {
                let (p0, p1) = (c.posed(&m0), c.posed(&m1));
                let v = ((p1.a + p1.b) - (p0.a + p0.b)) * (0.5 / frame_dt.max(1e-9));
                list.push(
                    Collider::Capsule {
                        a: p1.a.into(),
                        b: p1.b.into(),
                        radius: p1.r,
                        velocity: v.into(),
                    }
                    .to_gpu()?,
                );
            }
            st.set_colliders(&list)?;
        }
        Ok(())
    }

    /// After the frame's steps: the attached targets' metric copies, and the shown
    /// characters skinned to scene time `t` for the view.
    pub fn record_after(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        st: &SphState,
        t: f64,
        (frame, slot): (u64, usize),
    ) -> Result<()> {
        let emitting = self.emission.as_ref().map(|e| e.character);
        if let Some(e) = &mut self.emission {
            e.metrics.record(ctx, cmd, &e.emitter, slot, frame, t);
        }
        for (i, l) in self.live.iter().enumerate() {
            if let (Some((c, m)), Some(_)) = (&l.control, &l.poses[slot]) {
                {
                    let _scope = prof.open(ctx, cmd, CONTROL_METRICS_SCOPE);
                    m.record(ctx, cmd, st, &c.force, slot)?;
                }
            }
            // (The emitting character is already skinned at t, the frame's end.)
            if l.character.show != ShowMesh::Off && emitting != Some(i) {
                l.character.record(ctx, cmd, prof, t)?;
            }
        }
        Ok(())
    }

    /// The mesh the view draws: the first shown character (attached, if a target).
    pub fn draw(&self) -> Option<MeshDraw<'_>> {
        self.live
            .iter()
            .filter(|l| l.control.as_ref().is_none_or(|(c, _)| c.force.attached()))
            .find_map(|l| l.character.draw())
    }

    pub fn show(&self) -> ShowMesh {
        self.live
            .iter()
            .map(|l| l.character.show)
            .find(|s| *s != ShowMesh::Off)
            .unwrap_or(ShowMesh::Off)
    }

    /// After the slot's fence: the metrics of frame `frame` for every target it posed.
    pub fn retire(
        &mut self,
        slot: usize,
        frame: u64,
        fluid: &crate::sph::FluidParams,
    ) -> Result<()> {
        if let Some(e) = &mut self.emission {
            e.metrics.retire(slot);
        }
        for l in &mut self.live {
            let (Some((c, m)), Some((mats, before, time))) = (&mut l.control, l.poses[slot].take())
            else {
                continue;
            };
            // Skinned on the metrics' worker, off the frame loop.
            let skin = crate::control::metrics::Skin {
                ch: l.shared.clone(),
                mats,
                before,
                method: l.character.method,
                dt: SKIN_SPEED_DT,
            };
            let constants = crate::control::fidelity::Fluid {
                h: fluid.h,
                mass: fluid.mass,
                rest_density: fluid.rest_density,
                spacing: fluid.spacing(),
                floor: self.floor,
            };
            m.retire(
                slot,
                frame,
                time,
                skin,
                &c.force,
                c.force.settings.group,
                &constants,
            )?;
        }
        Ok(())
    }

    /// `stats.character`: the first character's (thin parts at the fluid's `spacing`).
    pub fn character_stats(&self, spacing: f32) -> Result<Option<CharacterStats>> {
        let first = self.live.first();
        first.map(|l| l.character.stats(Some(spacing))).transpose()
    }

    /// `stats.control` (None without control targets), and control.csv in `out`: every
    /// target's rows, by frame.
    pub fn control_summary(&mut self, out: &std::path::Path) -> Result<Option<ControlSummary>> {
        for l in &mut self.live {
            let ch = &l.character;
            let cycle = ch
                .anim
                .clip
                .map(|c| ch.ch.clips[c].duration as f64)
                .filter(|d| *d > 0.0 && ch.speed > 0.0)
                .map(|d| d / ch.speed as f64);
            if let Some((_, m)) = &mut l.control {
                m.flush()?;
                m.finish_cycle(cycle);
                m.finish_window(self.metrics_from);
            }
        }
        if self.controlled.is_empty() {
            return Ok(None);
        }
        let mut rows: Vec<_> = Vec::new();
        let mut targets = Vec::new();
        for &i in &self.controlled {
            let l = &self.live[i];
            let (c, m) = l.control.as_ref().expect("control");
            rows.extend(m.rows.iter().cloned());
            let mut s = m.stats.clone();
            s.settings = Some(c.force.settings.clone());
            s.placement = Some(c.desc.placement);
            targets.push(s);
        }
        rows.sort_by_key(|r| r.frame);
        crate::control::metrics::write_csv(&out.join("control.csv"), &rows)?;
        Ok(Some(ControlSummary {
            targets,
            events: self.fired.clone(),
        }))
    }

    /// `stats.emission` (None without emission) and emission.csv in `out`, after the run
    /// of `seconds` simulated seconds.
    pub fn emission_summary(
        &mut self,
        ctx: &Context,
        seconds: f64,
        out: &std::path::Path,
    ) -> Result<Option<EmissionStats>> {
        let Some(e) = &mut self.emission else {
            return Ok(None);
        };
        let mesh = &self.live[e.character].character.ch.mesh;
        e.metrics
            .finish(ctx, &e.emitter, mesh, (e.slots, seconds), out)
            .map(Some)
    }

    /// The emitter (tests and benches read its slots).
    pub fn emitter(&self) -> Option<&Emitter> {
        self.emission.as_ref().map(|e| &e.emitter)
    }

    /// The frame's hooks into the SPH step, lent for its steps: the emitter before
    /// arrange, each control target's force after the forces pass (in target order).
    pub fn hooks(&mut self) -> Hooks<'_> {
        let mut h = Hooks::default();
        if let Some(e) = &mut self.emission {
            h.pre_arrange.push(&mut e.emitter);
        }
        for l in &mut self.live {
            if let Some((c, _)) = &mut l.control {
                h.force.push(&mut c.force);
            }
        }
        h
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(e) = &mut self.emission {
            e.destroy(ctx);
        }
        for l in &mut self.live {
            if let Some((c, m)) = &mut l.control {
                m.destroy(ctx);
                c.force.destroy(ctx);
            }
            l.character.destroy(ctx);
        }
    }

    pub fn name(&self, i: usize) -> &str {
        &self.live[i].name
    }
}
crate::impl_destroy!(SceneTargets);
