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
    /// Frames to play; None: the scene's own count (orbits: 120).
    pub frames: Option<u64>,
    pub out: PathBuf,
    /// Save every k-th frame as PNG; 0 saves none.
    pub save_every: u64,
    pub switches: Switches,
}

pub const DEFAULT_SCENE: &str = "dam-break";

/// The run's outcome: the summary written and the validation counts.
pub struct RunResult {
    pub summary: Value,
    pub pngs: Vec<PathBuf>,
}

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
    let scene = crate::sph::Scene::load(&opts.scene)?;
    run_sph(opts, scene)
}

fn open(sw: &Switches) -> Result<Context> {
    Context::new(&ContextOptions {
        device: sw.device.clone(),
        validation: sw.validation,
    })
}

fn run_orbits(opts: &RunOptions) -> Result<RunResult> {
    let sw = &opts.switches;
    sw.reject_unimplemented("the orbits scene", &[])?;
    let ctx = open(sw)?;
    let particles = sw.particles.unwrap_or(4096);
    let frame_count = opts.frames.unwrap_or(120);
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
    let save = |f: u64| opts.save_every > 0 && f.is_multiple_of(opts.save_every);
    let mut pngs = Vec::new();
    let result = frames.run(
        &ctx,
        frame_count,
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
        "frames": frame_count,
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

/// The camera with --eye, --target and --fov applied.
pub fn camera_with_switches(mut cam: Camera, sw: &Switches) -> Camera {
    if let Some(e) = sw.eye {
        cam.eye = e.into();
    }
    if let Some(t) = sw.target {
        cam.target = t.into();
    }
    if let Some(f) = sw.fov {
        cam.fov_y_deg = f;
    }
    cam
}

fn run_sph(opts: &RunOptions, scene: crate::sph::Scene) -> Result<RunResult> {
    use crate::config::{Neighbors, RenderKind};
    use crate::sph::run::{check, physics_stats, Stepper};
    use crate::sph::SphSolver;
    use crate::viewer::Viewer;
    let sw = &opts.switches;
    let render = sw.render.unwrap_or(RenderKind::Metaballs);
    let mut allowed = vec!["sort", "neighbors", "fluid", "render"];
    allowed.extend(crate::config::CAMERA_SWITCHES);
    if render == RenderKind::Metaballs {
        allowed.extend(crate::config::METABALL_SWITCHES);
    }
    sw.reject_unimplemented(
        &format!("SPH scenes drawn as {}", render.as_str()),
        &allowed,
    )?;
    let mut scene = scene;
    scene.fluid = scene.fluid.with_overrides(&sw.fluid)?;
    let scene = match sw.particles {
        Some(n) => scene.with_particles(n),
        None => scene,
    };
    let frame_count = opts.frames.unwrap_or(scene.frames);
    let ctx = open(sw)?;
    let neighbors = sw.neighbors.unwrap_or(Neighbors::Grid);
    let mut solver = SphSolver::new(&ctx, neighbors, sw.sort)?;
    let parts = scene.particles(sw.seed);
    let mut st = solver.state(&ctx, &scene, &parts)?;
    let aspect = sw.width as f32 / sw.height as f32;
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
    let viewer = match render {
        RenderKind::Metaballs => Viewer::metaballs(&ctx, sw, cam, st.n, SLOTS),
        // Spheres of half the rest spacing.
        RenderKind::Points => Viewer::points(&ctx, sw, &cam, 0.5 * scene.fluid.spacing(), SLOTS),
    };
    let mut viewer = match viewer {
        Ok(v) => v,
        Err(e) => {
            st.destroy(&ctx);
            solver.destroy(&ctx);
            return Err(e);
        }
    };
    // Scopes per step: arrange (keys, sort, ranges, reorder), density, forces, integrate.
    let max_steps = match scene.fluid.cfl {
        Some(_) => crate::sph::params::MAX_SUBSTEPS,
        None => scene.fluid.substeps,
    };
    let mut frames = FrameLoop::new(&ctx, SLOTS, max_steps * 10 + 32)?;
    let stepper = std::cell::RefCell::new(Stepper::new(&ctx, &st, SLOTS)?);
    let save = |f: u64| opts.save_every > 0 && f.is_multiple_of(opts.save_every);
    let mut pngs = Vec::new();
    let n = st.n;
    let result = frames.run(
        &ctx,
        frame_count,
        |prof, cmd, frame, slot| {
            stepper
                .borrow_mut()
                .record_frame(&ctx, cmd, prof, &solver, &mut st, slot)?;
            viewer.record(&ctx, cmd, prof, st.pos(), st.attr(), n, slot, save(frame))
        },
        |frame, slot| {
            stepper.borrow_mut().retire_slot(slot);
            let path = save(frame).then(|| opts.out.join(format!("frame_{frame:04}.png")));
            viewer.retire(&ctx, slot, n, path.as_deref())?;
            pngs.extend(path);
            Ok(())
        },
    );
    let timings = std::mem::take(&mut frames.profiler.results);
    let memory = ctx.memory_bytes();
    let dump = if result.is_ok() {
        Some(st.read(&ctx))
    } else {
        None
    };
    let mut stepper = stepper.into_inner();
    let (steps, sim_time) = (stepper.steps_taken, stepper.sim_time);
    let render_stats = viewer.stats();
    stepper.destroy(&ctx);
    frames.destroy(&ctx);
    viewer.destroy(&ctx);
    st.destroy(&ctx);
    solver.destroy(&ctx);
    result?;
    let mut stats = physics_stats(&dump.expect("state read")?, &scene);
    stats["steps"] = json!(steps);
    stats["simulated_seconds"] = json!(sim_time);
    stats["render"] = render_stats;
    let config = json!({
        "command": "run",
        "scene": scene.name,
        "frames": frame_count,
        "save_every": opts.save_every,
        "particles": stats["particles"],
        "neighbors": neighbors.as_str(),
        "sort": solver.search.sort.as_str(),
        "render": render.as_str(),
        "fluid": scene.fluid,
        "switches": sw,
    });
    let report = Report {
        device: &ctx.info,
        config,
        timings: &timings,
        memory,
        stats: stats.clone(),
        validation: sw.validation.then(|| ctx.validation_counts()),
    };
    let summary = report.write(&opts.out)?;
    check_validation(&ctx)?;
    check(&stats)?;
    Ok(RunResult { summary, pngs })
}
