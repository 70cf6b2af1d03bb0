//! `run` of an SPH scene: the fluid stepped per frame with the scene's characters,
//! control targets, emission and particle systems, and the view.
use super::*;

/// An SPH scene: steps per frame and the view.
pub(super) struct SphWork {
    solver: crate::sph::SphSolver,
    st: crate::sph::SphState,
    stepper: crate::sph::stepper::Stepper,
    view: Box<dyn crate::run::view::FluidView>,
    pub(super) frames: Frames,
    export: Option<crate::export::ParticleExport>,
    targets: crate::run::targets::SceneTargets,
    /// The scene's particle systems, stepped once per frame after the fluid.
    systems: Option<crate::run::particles::SceneSystems>,
    /// The viewer's switches of the next frame: simulate it (false: paused, the picture
    /// redrawn) and draw it (false: re-simulating up to a scrubbed time). `run`: both on.
    pub(super) simulate: bool,
    pub(super) draw: bool,
    /// Per slot: whether its frame in flight simulated and drew.
    did: Vec<(bool, bool)>,
}

impl FrameWork for SphWork {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        self.did[slot] = (self.simulate, self.draw);
        if self.simulate {
            self.record_simulation(ctx, cmd, prof, frame, slot)?;
        }
        if !self.draw {
            return Ok(());
        }
        let save = self.frames.save(frame);
        let st = &self.st;
        let mesh = self.targets.draw();
        let overlay = self.systems.as_ref().map(|s| s.at(frame));
        let layers = crate::run::view::Layers {
            mesh: mesh.as_ref(),
            overlay: overlay
                .as_ref()
                .map(|o| o as &dyn crate::run::view::Overlay),
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
        let (simulated, drawn) = self.did[slot];
        // An unstable frame's picture is still kept (the window shows it), then the
        // error goes on.
        let checked = match simulated {
            true => self.retire_simulation(frame, slot),
            false => Ok(()),
        };
        if !drawn {
            return checked;
        }
        let save = self.frames.save(frame);
        let overlay = self.systems.as_ref().map(|s| s.at(frame));
        let overlay = overlay
            .as_ref()
            .map(|o| o as &dyn crate::run::view::Overlay);
        let pic = self.view.retire(ctx, slot, self.st.n, save, overlay)?;
        self.frames.store(frame, pic)?;
        checked
    }
}

impl SphWork {
    /// The frame's steps with the scene's characters, control, emission, export and
    /// particle systems.
    fn record_simulation(
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
        if let Some(e) = self.export.as_mut().filter(|e| e.due(frame)) {
            e.record(ctx, cmd, &self.st, slot, self.stepper.sim_time);
        }
        if let Some(s) = &mut self.systems {
            s.record_simulation(ctx, cmd, prof, frame, None)?;
        }
        Ok(())
    }

    fn retire_simulation(&mut self, frame: u64, slot: usize) -> Result<()> {
        self.stepper.retire_slot(slot, frame)?;
        self.targets.retire(slot, frame, &self.st.fluid)?;
        if let Some(e) = self.export.as_mut().filter(|e| e.due(frame)) {
            e.retire(frame, slot)?;
        }
        Ok(())
    }

    pub(super) fn stepper(&self) -> &crate::sph::stepper::Stepper {
        &self.stepper
    }

    pub(super) fn stepper_mut(&mut self) -> &mut crate::sph::stepper::Stepper {
        &mut self.stepper
    }

    pub(super) fn set_camera(&mut self, cam: &Camera) {
        self.view.set_camera(cam);
        if let Some(s) = &mut self.systems {
            s.cam = *cam;
        }
    }

    pub(super) fn particles(&self) -> u32 {
        self.st.n
    }

    pub(super) fn show(&self) -> ShowMesh {
        self.targets.show()
    }

    /// Use `view` from the next frame on (no frame may be in flight).
    pub(super) fn replace_view(
        &mut self,
        ctx: &Context,
        view: Box<dyn crate::run::view::FluidView>,
    ) {
        self.view.destroy(ctx);
        self.view = view;
        self.frames.latest = None;
    }

    /// (particles, simulated seconds, steps taken).
    pub(super) fn progress(&self) -> (u32, f64, u64) {
        let s = &self.stepper;
        (self.st.n, s.sim_time, s.steps_taken)
    }

    pub(super) fn render_stats(&self) -> crate::run::view::RenderSummary {
        self.view.stats()
    }

    pub(super) fn control_rows(&self) -> Vec<crate::control::metrics::ControlRow> {
        self.targets.latest_metrics()
    }

    pub(super) fn set_control(
        &mut self,
        sw: &Switches,
        fluid: &crate::sph::FluidParams,
    ) -> Result<bool> {
        self.targets
            .set_control(&crate::settings::control_overrides(sw), fluid)
    }

    pub(super) fn events(&self) -> Vec<(f32, String)> {
        self.targets.events()
    }

    pub(super) fn destroy(&mut self, ctx: &Context) {
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

pub(super) fn run_sph(opts: &RunOptions, scene: crate::scene::Scene) -> Result<RunResult> {
    let (scene, sw, render, neighbors) = plan(scene, &opts.switches)?;
    let sw = &sw;
    let frame_count = opts.frames.unwrap_or(scene.frames);
    let ctx = open(sw)?;
    fits(&ctx, &scene)?;
    let frames = Frames::new(&opts.out, opts.save_every, frame_count).sampled(&sw.frame);
    let mut work = SphWork::new(&ctx, (&opts.out, frames), &scene, sw, render, neighbors)?;
    let timings = play_run(&ctx, frame_count, &mut work, &opts.scene, &sw.common);
    let how = (sw, render, neighbors);
    work.finish(&ctx, opts, &scene, how, frame_count, timings)
}

/// What `run` and the viewer settle before an SPH scene's work: how it is drawn, the
/// switches it would not use refused, the scene prepared, the neighbour search.
pub(super) fn plan(
    scene: crate::scene::Scene,
    sw: &Switches,
) -> Result<(crate::scene::Scene, Switches, RenderKind, Neighbors)> {
    let render = (sw.view.render.or(scene.look.render)).unwrap_or(RenderKind::Metaballs);
    check_groups(sw, render, &scene)?;
    let (scene, sw) = prepare(scene, sw)?;
    let neighbors = sw.search.neighbors.unwrap_or(Neighbors::Grid);
    Ok((scene, sw, render, neighbors))
}

/// Refuse a scene whose particles the device cannot hold.
pub(super) fn fits(ctx: &Context, scene: &crate::scene::Scene) -> Result<()> {
    use crate::sph::solver::{bytes_per_particle, MAX_PARTICLES};
    let per_particle = bytes_per_particle(&scene.fluid);
    scene.check_size(MAX_PARTICLES, per_particle, ctx.info.device_local_bytes)
}

/// Refuse switches that an SPH scene drawn this way would not use.
fn check_groups(sw: &Switches, render: RenderKind, scene: &crate::scene::Scene) -> Result<()> {
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
    sw.reject_unused(&format!("SPH scenes drawn as {}", render.as_str()), &uses)
}

/// The scene as it will play and the switches with its look applied: fluid overrides,
/// the character's fit, the metaball radius from the spacing; validated and size-checked
/// before any particle or buffer is made (the count is estimated, not built).
fn prepare(scene: crate::scene::Scene, sw: &Switches) -> Result<(crate::scene::Scene, Switches)> {
    use crate::sph::solver::{bytes_per_particle, MAX_PARTICLES};
    let mut scene = scene;
    // The scene's look where the switches leave it open; summary.json records the result.
    let mut sw = crate::settings::with_look(&scene.look, sw);
    scene.fluid = sw.fluid_args.apply(&scene.fluid)?;
    // A liquid character's spacing and pool from its character (scene::fit).
    let mut lines = crate::scene::fit::fit(&mut scene)?.describe();
    // The step and the stopping rule the solver takes (its own unless [fluid] sets them).
    lines.push(scene.fluid.describe_step());
    for line in lines {
        if !sw.common.quiet {
            eprintln!("{}: {line}", scene.name);
        }
    }
    // The metaballs' radius follows the particle spacing (0.04 m at the default spacing).
    if sw.metaball.radius.is_none() && scene.fluid.spacing.is_some() {
        let s0 = crate::sph::FluidParams::default().spacing();
        sw.metaball.radius = Some(DEFAULT_RADIUS * scene.fluid.spacing() / s0);
    }
    crate::scene::particles::set_integrator_draw(
        &mut scene.system,
        sw.particle.integrator,
        sw.particle.draw,
    );
    scene.validate()?;
    scene.check_size(MAX_PARTICLES, bytes_per_particle(&scene.fluid), 0)?;
    let scene = match sw.common.particles {
        Some(n) => scene.with_particles(n),
        None => scene,
    };
    Ok((scene, sw))
}

/// The view of `scene`'s particles, drawn from `cam`, as `run` makes it.
pub(super) fn make_view(
    ctx: &Context,
    scene: &crate::scene::Scene,
    sw: &Switches,
    render: RenderKind,
    cam: &Camera,
    n: u32,
    show: ShowMesh,
) -> Result<Box<dyn FluidView>> {
    use crate::run::view::MetaballViewer;
    Ok(match render {
        RenderKind::Metaballs => {
            let tank = (scene.look.tank)
                .unwrap_or(true)
                .then_some([scene.domain.min, scene.domain.max]);
            let overlay = !scene.system.is_empty();
            let fluid = crate::render::surface::SurfaceFluid {
                spacing: scene.fluid.spacing(),
                h: scene.fluid.h,
                bounds: [scene.domain.min, scene.domain.max],
            };
            Box::new(MetaballViewer::new(
                ctx,
                sw,
                *cam,
                n,
                SLOTS,
                (tank, fluid),
                show,
                overlay,
            )?)
        }
        // Spheres of half the rest spacing.
        RenderKind::Points => Box::new(PointsViewer::new(
            ctx,
            sw,
            cam,
            0.5 * scene.fluid.spacing(),
            SLOTS,
            show,
        )?),
    })
}

/// The scene's camera, else one looking at the domain from the front and above.
pub(super) fn scene_camera(scene: &crate::scene::Scene, sw: &Switches) -> Camera {
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
    camera_with_switches(cam, sw)
}

impl SphWork {
    /// Solver, state, targets, view, stepper, particle systems and export of a scene;
    /// export files go to `out`, pictures to `frames`.
    pub(super) fn new(
        ctx: &Context,
        (out, frames): (&Path, Frames),
        scene: &crate::scene::Scene,
        sw: &Switches,
        render: RenderKind,
        neighbors: Neighbors,
    ) -> Result<Self> {
        use crate::sph::stepper::Stepper;
        use crate::sph::SphSolver;
        let mut solver = Guard::new(ctx, SphSolver::new(ctx, neighbors, sw.sorting.sort)?);
        let parts = scene.particles(sw.common.seed);
        let mut st = Guard::new(ctx, solver.state(ctx, scene, &parts)?);
        let cam = scene_camera(scene, sw);
        let opts = crate::settings::target_options(sw);
        let targets = crate::run::targets::SceneTargets::new(
            ctx, scene, &opts, &solver, &mut st, &parts.pos, SLOTS,
        )?;
        let targets = Guard::new(ctx, targets);
        let view = make_view(ctx, scene, sw, render, &cam, st.n, targets.show())?;
        let view = Guard::new(ctx, view);
        let stepper = Guard::new(ctx, Stepper::new(ctx, &st, SLOTS)?);
        let systems = match scene.system.is_empty() {
            true => None,
            false => Some(crate::run::particles::SceneSystems::new(
                ctx,
                &scene.system,
                stepper.frame_time as f32,
                cam,
                sw.frame.width(),
                sw.frame.height(),
                sw.common.seed,
            )?),
        };
        let systems = Guard::new(ctx, systems);
        let every = sw.export.export_every.unwrap_or(1);
        let formats = (sw.export.export, sw.export.export_mesh);
        let export = match formats {
            (None, None) => None,
            f => Some(crate::export::ParticleExport::new(
                ctx, f, every, out, &st, SLOTS,
            )?),
        };
        Ok(SphWork {
            solver: solver.take(),
            st: st.take(),
            stepper: stepper.take(),
            view: view.take(),
            frames,
            export,
            targets: targets.take(),
            systems: systems.take(),
            simulate: true,
            draw: true,
            did: vec![(false, false); SLOTS],
        })
    }

    /// After the frames: statistics read back, everything destroyed, the frames and
    /// summary.json written, then the validation and physics checks.
    fn finish(
        mut self,
        ctx: &Context,
        opts: &RunOptions,
        scene: &crate::scene::Scene,
        (sw, render, neighbors): (&Switches, RenderKind, Neighbors),
        frame_count: u64,
        timings: Result<Vec<crate::gpu::FrameTiming>>,
    ) -> Result<RunResult> {
        use crate::sph::stepper::{check, physics_stats};
        let memory = ctx.memory_bytes();
        let ok = timings.is_ok();
        let dump = ok.then(|| self.st.read(ctx));
        let (steps, simulated_seconds) = (self.stepper.steps_taken, self.stepper.sim_time);
        let density_error = self.stepper.error_stats(&self.st);
        let steps_csv = self.stepper.write_csv(&opts.out.join("steps.csv"));
        let render_stats = self.view.stats();
        let character_stats = (self.targets).character_stats(scene.fluid.spacing());
        let control_stats = self.targets.control_summary(&opts.out);
        let emission_stats = match ok {
            true => self
                .targets
                .emission_summary(ctx, simulated_seconds, &opts.out),
            false => Ok(None),
        };
        let particle_systems = match (ok, &self.systems) {
            (true, Some(s)) => s
                .systems
                .iter()
                .map(|s| crate::run::particles::SystemStats::of(ctx, s))
                .collect::<Result<Vec<_>>>(),
            _ => Ok(Vec::new()),
        };
        let sort = self.solver.search.sort;
        let exports = self
            .export
            .as_ref()
            .map(|e| e.files.clone())
            .unwrap_or_default();
        self.destroy(ctx);
        let timings = timings?;
        let animation = self.frames.finish()?;
        let stats = SphRunStats {
            physics: physics_stats(
                &dump.expect("state read")?,
                &scene.domain,
                scene.fluid.rest_density,
            ),
            steps,
            simulated_seconds,
            render: render_stats,
            character: character_stats?,
            control: control_stats?,
            emission: emission_stats?,
            particle_systems: particle_systems?,
            density_error,
            commands: self.stepper.commands.finished(),
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
            barriers: ctx.tracked_barriers(),
        };
        let summary = report.write(&opts.out)?;
        if let Some(path) = &sw.common.trace {
            crate::trace::write_run_trace(ctx, path, &timings)?;
        }
        check_validation(ctx)?;
        check(&physics)?;
        Ok(RunResult {
            summary,
            pngs: self.frames.pngs,
            animation,
            exports,
        })
    }
}
