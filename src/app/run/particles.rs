//! `fluidform run` for particle-system scenes: step, sort and draw every system per frame.
use crate::character::Skinning;
use crate::config::Group;
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{ColorTarget, Context, FrameWork, Guard, Profiler, Scopes};
use crate::kinds::SortAlgo;
use crate::psys::character::{CharacterBufs, CharacterLink};
use crate::psys::frame::{frame_info, record_simulation};
use crate::psys::gpu::Passes;
use crate::psys::spec::SystemSpec;
use crate::psys::system::{FrameInfo, ParticleSystem};
use crate::psys::{Integrator, SpriteMode};
use crate::render::mesh::MeshView;
use crate::render::Camera;
use crate::render::ShowMesh;
use crate::run::common::{camera_with_switches, open, play_run, SLOTS};
use crate::run::targets::character::SceneCharacter;
use crate::run::view::Picture;
use crate::run::{finish_fluidless, Frames, RunOptions, RunResult, RunStats};
use crate::scene::particles::ParticleScene;
use serde::{Deserialize, Serialize};

const READBACK_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("readback");

/// One system's totals in summary.json.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SystemStats {
    pub name: String,
    pub capacity: u32,
    pub integrator: Integrator,
    pub draw: SpriteMode,
    pub sort: SortAlgo,
    pub births: u64,
    /// Births per frame drawn on the CPU: mean and variance.
    pub births_per_frame_mean: f64,
    pub births_per_frame_variance: f64,
    /// Births refused: no free slot (the budget).
    pub refused: u64,
    /// Closed form: live particles overwritten by the ring (the budget).
    pub overwritten: u64,
    pub died_life: u64,
    pub died_view: u64,
    pub died_distance: u64,
    pub died_collision: u64,
    /// Parents that died by a collision event (changed type).
    pub changed: u64,
    /// Births from other systems' events, and those refused (no free slot).
    pub spawned: u64,
    pub spawn_refused: u64,
    /// Events lost: the event list was full.
    pub events_dropped: u64,
    /// Alive after the last frame (closed form: born within a life, not overwritten).
    pub alive: u64,
}

/// `stats` of a particle-system run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ParticleRunStats {
    pub systems: Vec<SystemStats>,
}

impl SystemStats {
    pub fn of(ctx: &Context, s: &ParticleSystem) -> Result<Self> {
        let c = s.read_counters(ctx)?;
        let frames = s.frames.max(1) as f64;
        let mean = s.births_sum.0 / frames;
        let alive = match s.closed() {
            true => s.read(ctx)?.live_closed(s.time_now()).len() as u64,
            false => c.alive[s.drawn() as usize] as u64,
        };
        Ok(Self {
            name: s.spec.name.clone(),
            capacity: s.capacity,
            integrator: s.spec.integrator(),
            draw: s.mode,
            sort: s.sort,
            births: c.births as u64,
            births_per_frame_mean: mean,
            births_per_frame_variance: (s.births_sum.1 / frames - mean * mean).max(0.0),
            refused: c.refused as u64 + s.refused_cpu,
            overwritten: c.overwritten as u64,
            died_life: c.died_life as u64,
            died_view: c.died_view as u64,
            died_distance: c.died_distance as u64,
            died_collision: c.died_collision as u64,
            changed: c.changed as u64,
            spawned: c.spawned as u64,
            spawn_refused: c.spawn_refused as u64,
            events_dropped: c.events_dropped as u64,
            alive,
        })
    }
}

/// The systems of a scene and the frame they are drawn in.
pub struct SceneSystems {
    pub passes: Passes,
    pub systems: Vec<ParticleSystem>,
    pub cam: Camera,
    pub dt: f32,
    pub width: u32,
    pub height: u32,
}

impl SceneSystems {
    /// `specs` stepped `dt` seconds per frame.
    pub fn new(
        ctx: &Context,
        specs: &[SystemSpec],
        dt: f32,
        cam: Camera,
        width: u32,
        height: u32,
        seed: u64,
    ) -> Result<Self> {
        let passes = Guard::new(ctx, Passes::new(ctx)?);
        let mut systems = Guard::new(ctx, Vec::new());
        for (i, spec) in specs.iter().enumerate() {
            systems.push(ParticleSystem::new(
                ctx,
                &passes,
                spec,
                i as u32,
                seed.wrapping_add(i as u64),
            )?);
        }
        Ok(Self {
            passes: passes.take(),
            systems: systems.take(),
            cam,
            dt,
            width,
            height,
        })
    }

    pub fn frame(&self, frame: u64) -> FrameInfo<'_> {
        frame_info(&self.cam, self.dt, frame, self.width, self.height)
    }

    /// Record every system's step and sort (see `record_simulation`), with the scene
    /// character's buffers when it has one.
    pub fn record_simulation(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut dyn Scopes,
        frame: u64,
        character: Option<CharacterBufs>,
    ) -> Result<()> {
        let f = FrameInfo {
            character,
            ..frame_info(&self.cam, self.dt, frame, self.width, self.height)
        };
        record_simulation(ctx, cmd, prof, &self.passes, &mut self.systems, &f)
    }

    /// Declare the draws of `record_draws` for the next rendering scope (before it begins).
    pub fn prepare_draws(&self, ctx: &Context, cmd: vk::CommandBuffer, frame: u64, opaque: bool) {
        let f = self.frame(frame);
        for s in self.systems.iter().filter(|s| s.opaque() == opaque) {
            s.prepare_draw(ctx, cmd, &self.passes, &f);
        }
    }

    /// Record the draws (inside a rendering scope) of the systems drawn as points
    /// (opaque, depth-written) or of the others (alpha-blended, depth-tested only).
    pub fn record_draws(&self, ctx: &Context, cmd: vk::CommandBuffer, frame: u64, opaque: bool) {
        let f = self.frame(frame);
        for s in self.systems.iter().filter(|s| s.opaque() == opaque) {
            s.record_draw(ctx, cmd, &self.passes, &f);
        }
    }

    /// Frame `frame`'s draws as a view's overlay.
    pub fn at(&self, frame: u64) -> SystemsFrame<'_> {
        SystemsFrame { scene: self, frame }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for s in &mut self.systems {
            s.destroy(ctx);
        }
        self.passes.destroy(ctx);
    }
}
crate::impl_destroy!(SceneSystems);

/// A scene's systems drawn at a frame, as a view's overlay.
pub struct SystemsFrame<'a> {
    scene: &'a SceneSystems,
    frame: u64,
}

impl crate::run::view::Overlay for SystemsFrame<'_> {
    fn prepare(&self, ctx: &Context, cmd: vk::CommandBuffer, opaque: bool) {
        self.scene.prepare_draws(ctx, cmd, self.frame, opaque);
    }

    fn draw_opaque(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.scene.record_draws(ctx, cmd, self.frame, true);
    }

    fn draw_blended(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.scene.record_draws(ctx, cmd, self.frame, false);
    }

    fn has_blended(&self) -> bool {
        self.scene.systems.iter().any(|s| !s.opaque())
    }
}

/// The scene character: skinned each frame, its capsules posed for the colliders, its
/// mesh drawn (unless --show-mesh off) before the particles, so they are depth-tested
/// against it.
struct Body {
    ch: SceneCharacter,
    link: CharacterLink,
    view: Option<MeshView>,
}

impl Body {
    fn destroy(&mut self, ctx: &Context) {
        self.ch.destroy(ctx);
        self.link.destroy(ctx);
        if let Some(v) = &mut self.view {
            v.destroy(ctx);
        }
    }
}
crate::impl_destroy!(Body);

struct ParticleWork {
    body: Option<Body>,
    scene: SceneSystems,
    target: ColorTarget,
    background: [f32; 3],
    frames: Frames,
}

impl FrameWork for ParticleWork {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        if let Some(body) = &self.body {
            let t = frame as f64 * self.scene.dt as f64;
            body.ch.record(ctx, cmd, prof, t)?;
            body.link.record(ctx, cmd, &body.ch.matrices(t));
        }
        let bufs = self.body.as_ref().map(|b| b.link.bufs(b.ch.surface()));
        self.scene.record_simulation(ctx, cmd, prof, frame, bufs)?;
        {
            let _scope = prof.open(ctx, cmd, Passes::DRAW);
            let mesh = match &self.body {
                Some(Body {
                    ch, view: Some(v), ..
                }) => Some((v, ch.surface())),
                _ => None,
            };
            if let Some((v, m)) = &mesh {
                v.prepare(ctx, cmd, m);
            }
            self.scene.prepare_draws(ctx, cmd, frame, true);
            self.scene.prepare_draws(ctx, cmd, frame, false);
            let b = self.background;
            self.target
                .begin_rendering(ctx, cmd, [b[0], b[1], b[2], 1.0]);
            if let Some((v, m)) = &mesh {
                v.draw(ctx, cmd, m);
            }
            // Opaque points first, so the blended draws after them are depth-tested against them.
            self.scene.record_draws(ctx, cmd, frame, true);
            self.scene.record_draws(ctx, cmd, frame, false);
            self.target.end_rendering(ctx, cmd);
        }
        if self.frames.save(frame) {
            {
                let _scope = prof.open(ctx, cmd, READBACK_SCOPE);
                self.target.copy_out(ctx, cmd, slot);
            }
        }
        Ok(())
    }

    fn retire(&mut self, _: &Context, frame: u64, slot: usize) -> Result<()> {
        let pic = self.frames.save(frame).then(|| Picture {
            rgba: self.target.pixels(slot),
            width: self.target.width(),
            height: self.target.height(),
        });
        self.frames.store(frame, pic)
    }
}

pub fn run(opts: &RunOptions, scene: ParticleScene) -> Result<RunResult> {
    let sw = &opts.switches;
    let mut groups = vec![Group::Particles, Group::Sort, Group::Camera];
    if scene.character.is_some() {
        groups.push(Group::Character);
    }
    sw.reject_unused(&format!("particle-system scene {}", scene.name), &groups)?;
    let scene = scene.with_switches(
        sw.particle.integrator,
        sw.particle.draw,
        sw.sorting.sort,
        sw.common.particles,
    )?;
    let frame_count = opts.frames.unwrap_or(scene.frames);
    let ctx = open(sw)?;
    let (w, h) = (sw.frame.width(), sw.frame.height());
    let c = &scene.camera;
    let cam = camera_with_switches(
        Camera::look_at(c.eye.into(), c.target.into(), c.fov, w as f32 / h as f32),
        sw,
    );
    let systems = Guard::new(
        &ctx,
        SceneSystems::new(&ctx, &scene.system, scene.dt, cam, w, h, sw.common.seed)?,
    );
    let body = match &scene.character {
        Some(desc) => {
            let show = sw.character.show_mesh.unwrap_or(ShowMesh::Shaded);
            let method = sw.character.skinning.unwrap_or(Skinning::Lbs);
            let ch = Guard::new(&ctx, SceneCharacter::new(&ctx, desc, method, show)?);
            let link = Guard::new(&ctx, CharacterLink::new(&ctx, &ch.ch)?);
            let view = match show {
                ShowMesh::Off => None,
                s => Some(MeshView::new(&ctx, &cam, s)?),
            };
            Some(Body {
                ch: ch.take(),
                link: link.take(),
                view,
            })
        }
        None => None,
    };
    let body = Guard::new(&ctx, body);
    let target = ColorTarget::new(&ctx, w, h, SLOTS)?;
    let mut work = ParticleWork {
        body: body.take(),
        scene: systems.take(),
        target,
        background: scene.background,
        frames: Frames::new(&opts.out, opts.save_every, frame_count).sampled(&sw.frame),
    };
    let memory = ctx.memory_bytes();
    let timings = play_run(&ctx, frame_count, &mut work, &scene.name, &sw.common);
    let stats = match &timings {
        Ok(_) => work
            .scene
            .systems
            .iter()
            .map(|s| SystemStats::of(&ctx, s))
            .collect::<Result<Vec<_>>>(),
        Err(_) => Ok(Vec::new()),
    };
    let particles = work.scene.systems.iter().map(|s| s.capacity as u64).sum();
    work.scene.destroy(&ctx);
    work.target.destroy(&ctx);
    if let Some(b) = &mut work.body {
        b.destroy(&ctx);
    }
    let timings = timings?;
    finish_fluidless(
        &ctx,
        opts,
        sw,
        (&scene.name, frame_count, particles),
        (&timings, memory),
        RunStats::Particles(Box::new(ParticleRunStats { systems: stats? })),
        work.frames,
    )
}
