//! `fluidform run`: play a scene for N frames, write PNGs, timings.csv and summary.json.
//! Every scene kind is a `FrameWork` played by `session::play`.
use crate::animation::Animation;
use crate::config::Switches;
use crate::config::{Neighbors, RenderKind, ShowMesh, Skinning, SortAlgo};
use crate::error::{Error, Result};
use crate::gpu::target::save_rgba;
use crate::gpu::{sync, Context, FrameWork, Guard, Profiler};
use crate::render::Camera;
use crate::report::{Report, Summary};
use crate::scene::character::{CharacterStats, SceneCharacter};
use crate::scene::orbits::{self, Orbits, OrbitsPass};
pub use crate::session::{camera_with_switches, check_validation, SLOTS};
use crate::session::{open, play};
use crate::sph::run::SphRunStats;
use crate::sph::FluidParams;
use crate::viewer::{Picture, PointsViewer, View};
use ash::vk;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

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

/// `stats` of the orbits scene (strict, so an SPH block never reads back as this).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OrbitsStats {
    pub particles: u32,
}

/// `stats` of a scene with a character and no fluid.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CharacterRunStats {
    pub character: CharacterStats,
    pub render: crate::viewer::RenderSummary,
}

/// `stats` of a run, by scene kind.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum RunStats {
    Sph(Box<SphRunStats>),
    Character(Box<CharacterRunStats>),
    Orbits(OrbitsStats),
    Particles(Box<crate::psys::run::ParticleRunStats>),
}

pub type RunSummary = Summary<RunConfig, RunStats>;

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

/// Where saved frames go: frame_NNNN.png each, and animation.png (APNG) of them all.
pub(crate) struct Frames<'a> {
    out: &'a Path,
    every: u64,
    /// Frames the run plays.
    total: u64,
    pngs: Vec<PathBuf>,
    animation: Option<Animation>,
}

impl<'a> Frames<'a> {
    pub(crate) fn new(out: &'a Path, every: u64, total: u64) -> Self {
        Self {
            out,
            every,
            total,
            pngs: Vec::new(),
            animation: None,
        }
    }

    pub(crate) fn save(&self, f: u64) -> bool {
        self.every > 0 && f.is_multiple_of(self.every)
    }

    /// Write frame `f`'s picture as a PNG and as the animation's next frame.
    pub(crate) fn store(&mut self, f: u64, pic: Option<Picture>) -> Result<()> {
        let Some(pic) = pic else { return Ok(()) };
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
    if let Some(scene) = crate::psys::scenes::ParticleScene::find(&opts.scene)? {
        return crate::psys::run::run(opts, scene);
    }
    let scene = crate::sph::Scene::load(&opts.scene)?;
    match scene.has_fluid() {
        true => run_sph(opts, scene),
        false => run_character(opts, scene),
    }
}

/// The orbits scene: a gravity step and the point view per frame.
struct OrbitsWork<'a> {
    pass: OrbitsPass,
    view: PointsViewer,
    scene: Orbits,
    frames: Frames<'a>,
}

impl FrameWork for OrbitsWork<'_> {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        prof.begin(ctx, cmd, OrbitsPass::NAME);
        self.pass.step(ctx, cmd, &self.scene, 1.0 / 120.0);
        prof.end(ctx, cmd);
        // New positions -> the point view's vertex shader.
        ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::GRAPHICS_READ);
        let (s, save) = (&self.scene, self.frames.save(frame));
        self.view.record(
            ctx,
            cmd,
            prof,
            &s.pos,
            &s.color,
            s.n,
            Default::default(),
            slot,
            save,
        )
    }

    fn retire(&mut self, ctx: &Context, frame: u64, slot: usize) -> Result<()> {
        let save = self.frames.save(frame);
        let pic = self.view.retire(ctx, slot, self.scene.n, save, None)?;
        self.frames.store(frame, pic)
    }
}

impl OrbitsWork<'_> {
    fn destroy(&mut self, ctx: &Context) {
        self.scene.destroy(ctx);
        self.view.destroy(ctx);
        self.pass.destroy(ctx);
    }
}

fn run_orbits(opts: &RunOptions) -> Result<RunResult> {
    let sw = &opts.switches;
    sw.reject_unused("the orbits scene", &[])?;
    let ctx = open(sw)?;
    let particles = sw.common.particles.unwrap_or(4096);
    let frame_count = opts.frames.unwrap_or(120);
    let state = orbits::initial_state(particles as usize, sw.common.seed);
    let cam = Camera::look_at(
        glam::Vec3::new(0.0, 0.8, 3.2),
        glam::Vec3::ZERO,
        45.0,
        sw.frame.width() as f32 / sw.frame.height() as f32,
    );
    let pass = Guard::new(&ctx, OrbitsPass::new(&ctx)?);
    let scene = Guard::new(&ctx, Orbits::new(&ctx, &state)?);
    let view = PointsViewer::new(&ctx, sw, &cam, 1.0, SLOTS, ShowMesh::Off)?;
    let mut work = OrbitsWork {
        pass: pass.take(),
        view,
        scene: scene.take(),
        frames: Frames::new(&opts.out, opts.save_every, frame_count),
    };
    let memory = ctx.memory_bytes();
    let timings = play(&ctx, frame_count, &mut work, &opts.scene, sw.common.quiet);
    work.destroy(&ctx);
    let timings = timings?;
    finish_fluidless(
        &ctx,
        opts,
        sw,
        (&opts.scene, frame_count, particles as u64),
        (&timings, memory),
        RunStats::Orbits(OrbitsStats { particles }),
        work.frames,
    )
}

/// An SPH scene: steps per frame and the view.
struct SphWork<'a> {
    solver: crate::sph::SphSolver,
    st: crate::sph::SphState,
    stepper: crate::sph::run::Stepper,
    view: Box<dyn crate::viewer::View>,
    frames: Frames<'a>,
    export: Option<crate::export::ParticleExport>,
    targets: crate::scene::targets::SceneTargets,
    /// The scene's particle systems, stepped once per frame after the fluid.
    systems: Option<crate::psys::run::SceneSystems>,
}

impl FrameWork for SphWork<'_> {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        let frame_dt = self.stepper.frame_time as f32;
        self.targets
            .record_poses(frame, self.stepper.sim_time, frame_dt, slot)?;
        let (steps, _) = self.stepper.plan(&self.st);
        let t0 = self.stepper.sim_time;
        self.targets
            .record_before(ctx, cmd, prof, &mut self.st, t0, frame_dt, steps)?;
        let hooks = &mut self.targets.hooks();
        self.stepper
            .record_frame(ctx, cmd, prof, &self.solver, &mut self.st, (slot, hooks))?;
        let t = self.stepper.sim_time;
        self.targets
            .record_after(ctx, cmd, prof, &self.st, t, (frame, slot))?;
        // The step's positions -> the view's copies and shaders.
        ctx.barrier(
            cmd,
            sync::COMPUTE_WRITE,
            sync::TRANSFER_READ | sync::GRAPHICS_READ,
        );
        if let Some(e) = self.export.as_mut().filter(|e| e.due(frame)) {
            e.record(ctx, cmd, &self.st, slot, self.stepper.sim_time);
        }
        if let Some(s) = &mut self.systems {
            s.record_simulation(ctx, cmd, prof, frame, None)?;
        }
        let save = self.frames.save(frame);
        let st = &self.st;
        let mesh = self.targets.draw();
        let overlay = self.systems.as_ref().map(|s| s.at(frame));
        let layers = crate::viewer::Layers {
            mesh: mesh.as_ref(),
            overlay: overlay.as_ref().map(|o| o as &dyn crate::viewer::Overlay),
        };
        self.view.record(
            ctx,
            cmd,
            prof,
            st.pos(),
            st.attr(),
            st.n,
            layers,
            slot,
            save,
        )
    }

    fn retire(&mut self, ctx: &Context, frame: u64, slot: usize) -> Result<()> {
        self.stepper.retire_slot(slot, frame)?;
        self.targets.retire(slot, frame, &self.st.fluid)?;
        if let Some(e) = self.export.as_mut().filter(|e| e.due(frame)) {
            e.retire(frame, slot)?;
        }
        let save = self.frames.save(frame);
        let overlay = self.systems.as_ref().map(|s| s.at(frame));
        let overlay = overlay.as_ref().map(|o| o as &dyn crate::viewer::Overlay);
        let pic = self.view.retire(ctx, slot, self.st.n, save, overlay)?;
        self.frames.store(frame, pic)
    }
}

impl SphWork<'_> {
    fn destroy(&mut self, ctx: &Context) {
        self.stepper.destroy(ctx);
        if let Some(e) = &mut self.export {
            e.destroy(ctx);
        }
        self.view.destroy(ctx);
        if let Some(s) = &mut self.systems {
            s.destroy(ctx);
        }
        self.targets.destroy(ctx);
        self.st.destroy(ctx);
        self.solver.destroy(ctx);
    }
}

fn run_sph(opts: &RunOptions, scene: crate::sph::Scene) -> Result<RunResult> {
    use crate::sph::run::{check, physics_stats, Stepper};
    use crate::sph::SphSolver;
    use crate::viewer::{MetaballViewer, PointsViewer, View};
    let sw = &opts.switches;
    let render = sw
        .view
        .render
        .or(scene.look.render)
        .unwrap_or(RenderKind::Metaballs);
    use crate::config::Group;
    let mut uses = vec![
        Group::Sort,
        Group::Neighbors,
        Group::Fluid,
        Group::View,
        Group::Export,
        Group::Camera,
    ];
    if render == RenderKind::Metaballs {
        uses.push(Group::Metaball);
    }
    if scene.character.is_some() || !scene.targets.is_empty() {
        uses.push(Group::Character);
    }
    if !scene.control_targets().is_empty() {
        uses.push(Group::Control);
    }
    if scene.emission.is_some() {
        uses.push(Group::Emission);
    }
    if !scene.system.is_empty() {
        uses.push(Group::Particles);
    }
    sw.reject_unused(&format!("SPH scenes drawn as {}", render.as_str()), &uses)?;
    use crate::sph::solver::{bytes_per_particle, MAX_PARTICLES};
    let mut scene = scene;
    // The scene's look where the switches leave it open; summary.json records the result.
    let mut sw = scene.look.apply(sw);
    scene.fluid = scene.fluid.with_overrides(&sw.fluid_args)?;
    // A liquid character's spacing and pool from its character (scene::fit).
    for line in crate::scene::fit::fit(&mut scene)?.describe() {
        if !sw.common.quiet {
            eprintln!("{}: {line}", scene.name);
        }
    }
    // The metaballs' radius follows the particle spacing (0.04 m at the default spacing).
    if sw.metaball.radius.is_none() && scene.fluid.spacing.is_some() {
        let s0 = crate::sph::FluidParams::default().spacing();
        sw.metaball.radius = Some(DEFAULT_RADIUS * scene.fluid.spacing() / s0);
    }
    let sw = &sw;
    crate::psys::scenes::set_integrator_draw(
        &mut scene.system,
        sw.particle.integrator,
        sw.particle.draw,
    );
    // Refused before any particle or buffer is made (the count is estimated, not built).
    scene.validate()?;
    let per_particle = bytes_per_particle(&scene.fluid);
    scene.check_size(MAX_PARTICLES, per_particle, 0)?;
    let scene = match sw.common.particles {
        Some(n) => scene.with_particles(n),
        None => scene,
    };
    let frame_count = opts.frames.unwrap_or(scene.frames);
    let ctx = open(sw)?;
    scene.check_size(MAX_PARTICLES, per_particle, ctx.info.device_local_bytes)?;
    let neighbors = sw.search.neighbors.unwrap_or(Neighbors::Grid);
    let mut solver = Guard::new(&ctx, SphSolver::new(&ctx, neighbors, sw.sorting.sort)?);
    let parts = scene.particles(sw.common.seed);
    let mut st = Guard::new(&ctx, solver.state(&ctx, &scene, &parts)?);
    let aspect = sw.frame.width() as f32 / sw.frame.height() as f32;
    let cam = match &scene.camera {
        Some(c) => Camera::look_at(c.eye.into(), c.target.into(), c.fov, aspect),
        None => {
            let (lo, hi) = (
                glam::Vec3::from(scene.domain.min),
                glam::Vec3::from(scene.domain.max),
            );
            let c = 0.5 * (lo + hi);
            Camera::look_at(
                c + glam::Vec3::new(0.0, 0.4, 1.6) * (hi - lo).length(),
                c,
                45.0,
                aspect,
            )
        }
    };
    let cam = camera_with_switches(cam, sw);
    let targets = crate::scene::targets::SceneTargets::new(
        &ctx,
        &scene,
        sw,
        &mut solver,
        &mut st,
        &parts.pos,
        SLOTS,
    )?;
    let targets = Guard::new(&ctx, targets);
    let show = targets.show();
    let view: Box<dyn View> = match render {
        RenderKind::Metaballs => {
            let tank = scene
                .look
                .tank
                .unwrap_or(true)
                .then_some([scene.domain.min, scene.domain.max]);
            let overlay = !scene.system.is_empty();
            Box::new(MetaballViewer::new(
                &ctx, sw, cam, st.n, SLOTS, tank, show, overlay,
            )?)
        }
        // Spheres of half the rest spacing.
        RenderKind::Points => Box::new(PointsViewer::new(
            &ctx,
            sw,
            &cam,
            0.5 * scene.fluid.spacing(),
            SLOTS,
            show,
        )?),
    };
    let view = Guard::new(&ctx, view);
    let stepper = Guard::new(&ctx, Stepper::new(&ctx, &st, SLOTS)?);
    let systems = match scene.system.is_empty() {
        true => None,
        false => Some(crate::psys::run::SceneSystems::new(
            &ctx,
            &scene.system,
            stepper.frame_time as f32,
            cam,
            sw.frame.width(),
            sw.frame.height(),
            sw.common.seed,
        )?),
    };
    let systems = Guard::new(&ctx, systems);
    let every = sw.export.export_every.unwrap_or(1);
    let export = sw
        .export
        .export
        .map(|f| crate::export::ParticleExport::new(&ctx, f, every, &opts.out, &st, SLOTS))
        .transpose()?;
    let mut work = SphWork {
        solver: solver.take(),
        st: st.take(),
        stepper: stepper.take(),
        view: view.take(),
        frames: Frames::new(&opts.out, opts.save_every, frame_count),
        export,
        targets: targets.take(),
        systems: systems.take(),
    };
    let timings = play(&ctx, frame_count, &mut work, &opts.scene, sw.common.quiet);
    let memory = ctx.memory_bytes();
    let dump = match &timings {
        Ok(_) => Some(work.st.read(&ctx)),
        Err(_) => None,
    };
    let (steps, simulated_seconds) = (work.stepper.steps_taken, work.stepper.sim_time);
    let density_error = work.stepper.error_stats(&work.st);
    let steps_csv = work.stepper.write_csv(&opts.out.join("steps.csv"));
    let render_stats = work.view.stats();
    let character_stats = work.targets.character_stats();
    let control_stats = work.targets.control_summary(&opts.out);
    let emission_stats = match &timings {
        Ok(_) => work
            .targets
            .emission_summary(&ctx, simulated_seconds, &opts.out),
        Err(_) => Ok(None),
    };
    let particle_systems = match (&timings, &work.systems) {
        (Ok(_), Some(s)) => s
            .systems
            .iter()
            .map(|s| crate::psys::run::SystemStats::of(&ctx, s))
            .collect::<Result<Vec<_>>>(),
        _ => Ok(Vec::new()),
    };
    let sort = work.solver.search.sort;
    let exports = work
        .export
        .as_ref()
        .map(|e| e.files.clone())
        .unwrap_or_default();
    work.destroy(&ctx);
    let timings = timings?;
    let animation = work.frames.finish()?;
    let stats = SphRunStats {
        physics: physics_stats(&dump.expect("state read")?, &scene),
        steps,
        simulated_seconds,
        render: render_stats,
        character: character_stats?,
        control: control_stats?,
        emission: emission_stats?,
        particle_systems: particle_systems?,
        density_error,
    };
    steps_csv?;
    let config = RunConfig {
        command: "run".into(),
        scene: scene.name.clone(),
        frames: frame_count,
        save_every: opts.save_every,
        particles: stats.physics.particles as u64,
        neighbors: Some(neighbors),
        sort: Some(sort),
        render: Some(render),
        fluid: Some(scene.fluid.clone()),
        switches: sw.clone(),
    };
    let physics = stats.physics.clone();
    let report = Report {
        device: &ctx.info,
        config,
        timings: &timings,
        memory,
        stats: RunStats::Sph(Box::new(stats)),
        validation: sw.common.validation.then(|| ctx.validation_counts()),
    };
    let summary = report.write(&opts.out)?;
    check_validation(&ctx)?;
    check(&physics)?;
    Ok(RunResult {
        summary,
        pngs: work.frames.pngs,
        animation,
        exports,
    })
}

/// The scene's character, skinned by --skinning and shown by --show-mesh (default shaded).
fn scene_character(
    ctx: &Context,
    scene: &crate::sph::Scene,
    sw: &Switches,
) -> Result<Option<SceneCharacter>> {
    let method = sw.character.skinning.unwrap_or(Skinning::Lbs);
    // (Scenes with fluid, and so any control target, play through SceneTargets.)
    let show = sw.character.show_mesh.unwrap_or(ShowMesh::Shaded);
    scene
        .character
        .as_ref()
        .map(|d| SceneCharacter::new(ctx, d, method, show))
        .transpose()
}

/// A character alone: skinned each frame at 30 frames per second of scene time.
struct CharacterWork<'a> {
    character: SceneCharacter,
    view: PointsViewer,
    frames: Frames<'a>,
}

impl FrameWork for CharacterWork<'_> {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        let t = frame as f64 / ANIMATION_FPS as f64;
        self.character.record(ctx, cmd, prof, t)?;
        let save = self.frames.save(frame);
        let m = self.character.draw();
        // Without fluid the mesh is always shown (run_character refuses --show-mesh off).
        let Some(pos) = m.as_ref().map(|m| m.pos) else {
            return Err(Error::Param(
                "a character scene with its mesh hidden".into(),
            ));
        };
        let layers = crate::viewer::Layers {
            mesh: m.as_ref(),
            overlay: None,
        };
        self.view
            .record(ctx, cmd, prof, pos, pos, 0, layers, slot, save)
    }

    fn retire(&mut self, ctx: &Context, frame: u64, slot: usize) -> Result<()> {
        let save = self.frames.save(frame);
        let pic = self.view.retire(ctx, slot, 0, save, None)?;
        self.frames.store(frame, pic)
    }
}

fn run_character(opts: &RunOptions, scene: crate::sph::Scene) -> Result<RunResult> {
    use crate::config::Group;
    let sw = &scene.look.apply(&opts.switches);
    sw.reject_unused(
        &format!("scene {} (a character with no fluid)", scene.name),
        &[Group::Character, Group::Camera],
    )?;
    if sw.character.show_mesh == Some(ShowMesh::Off) {
        return Err(Error::Param(format!(
            "scene {} has no fluid: --show-mesh off leaves nothing to draw",
            scene.name
        )));
    }
    let frame_count = opts.frames.unwrap_or(scene.frames);
    let ctx = open(sw)?;
    let aspect = sw.frame.width() as f32 / sw.frame.height() as f32;
    let character = scene_character(&ctx, &scene, sw)?
        .ok_or_else(|| Error::Param(format!("scene {}: no fluid and no character", scene.name)))?;
    let character = Guard::new(&ctx, character);
    let cam = match &scene.camera {
        Some(c) => Camera::look_at(c.eye.into(), c.target.into(), c.fov, aspect),
        None => {
            let st = character.stats()?;
            let h = st.height.max(1e-3);
            let base = character.anim.placement.w_axis.truncate();
            let c = base + glam::Vec3::Y * 0.5 * h;
            Camera::look_at(
                c + glam::Vec3::new(0.6, 0.3, 1.6) * h * 1.3,
                c,
                40.0,
                aspect,
            )
        }
    };
    let cam = camera_with_switches(cam, sw);
    let view = PointsViewer::new(&ctx, sw, &cam, 1.0, SLOTS, character.show)?;
    let mut work = CharacterWork {
        character: character.take(),
        view,
        frames: Frames::new(&opts.out, opts.save_every, frame_count),
    };
    let memory = ctx.memory_bytes();
    let timings = play(&ctx, frame_count, &mut work, &opts.scene, sw.common.quiet);
    let stats = work.character.stats();
    let render = work.view.stats();
    work.character.destroy(&ctx);
    work.view.destroy(&ctx);
    let timings = timings?;
    let stats = RunStats::Character(Box::new(CharacterRunStats {
        character: stats?,
        render,
    }));
    finish_fluidless(
        &ctx,
        opts,
        sw,
        (&scene.name, frame_count, 0),
        (&timings, memory),
        stats,
        work.frames,
    )
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
    };
    let summary = report.write(&opts.out)?;
    check_validation(ctx)?;
    Ok(RunResult {
        summary,
        pngs: saved.pngs,
        animation,
        exports: Vec::new(),
    })
}
