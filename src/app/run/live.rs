//! A scene playing in a window (`fluidform view`): the same `SphWork` that `run` plays,
//! made from the same scene file and switches by the same functions, its every picture
//! kept for the swapchain instead of written. The window pauses, steps, moves the
//! camera and swaps the view; anything else it changes rebuilds the scene.
use super::sph::{fits, make_view, plan, scene_camera, SphWork};
use super::*;
use crate::gpu::FrameLoop;

pub struct LiveScene {
    work: SphWork,
    pub scene: crate::scene::Scene,
    /// The switches as the scene applied them (its look, the metaball radius).
    pub sw: Switches,
    render: RenderKind,
    /// The scene's camera with the switches' --eye, --target, --fov.
    pub home: Camera,
    pub cam: Camera,
    /// Simulated seconds per window frame at speed 1.
    frame_time: f64,
    pub frames: FrameLoop,
    /// The next frame's number.
    pub frame: u64,
    /// Why the simulation went unstable, found while settling (the window pauses).
    pub unstable: Option<String>,
}

/// What the overlay shows of the scene.
pub struct LiveStats {
    pub particles: u32,
    pub sim_time: f64,
    pub steps: u64,
    pub render: crate::run::view::RenderSummary,
    pub memory_bytes: u64,
    pub control: Vec<crate::control::metrics::ControlRow>,
}

impl LiveScene {
    /// The SPH scene `name` with `sw` (its size the window's), ready for frame 0.
    pub fn open(ctx: &Context, name: &str, sw: &Switches) -> Result<Self> {
        if crate::scene::particles::ParticleScene::find(name)?.is_some() || name == "orbits" {
            return Err(Error::Unsupported(format!(
                "view plays SPH scenes; '{name}' is a particle-system scene: use `fluidform run --scene {name}`"
            )));
        }
        if sw.export.export.is_some() || sw.export.export_mesh.is_some() {
            return Err(Error::Param(
                "view does not export particle files: use `fluidform run --export`".into(),
            ));
        }
        let scene = crate::scene::Scene::load(name)?;
        if !scene.has_fluid() {
            return Err(Error::Unsupported(format!(
                "view plays SPH scenes; '{name}' has no fluid: use `fluidform run --scene {name}`"
            )));
        }
        let (scene, sw, render, neighbors) = plan(scene, sw)?;
        fits(ctx, &scene)?;
        let out = Path::new("");
        let mut work = SphWork::new(ctx, (out, Frames::kept()), &scene, &sw, render, neighbors)?;
        let frames = match FrameLoop::new(ctx, SLOTS) {
            Ok(f) => f,
            Err(e) => {
                work.destroy(ctx);
                return Err(e);
            }
        };
        let home = scene_camera(&scene, &sw);
        Ok(Self {
            frame_time: work.stepper().frame_time,
            work,
            scene,
            sw,
            render,
            home,
            cam: home,
            frames,
            frame: 0,
            unstable: None,
        })
    }

    /// Play one window frame: simulate it unless `paused`, draw it unless `fast` (a scrub
    /// re-simulating). The picture shows frames later, once its slot retires.
    pub fn step(&mut self, ctx: &Context, paused: bool, fast: bool) -> Result<()> {
        self.work.simulate = !paused;
        self.work.draw = !fast;
        self.frames.step(ctx, self.frame, &mut self.work)?;
        self.frame += 1;
        // Bounded memory: the overlay reads only the last frames' timings.
        let r = &mut self.frames.profiler.results;
        if r.len() > 600 {
            r.drain(..r.len() - 300);
        }
        Ok(())
    }

    /// Wait for every frame in flight, so the newest picture is the newest frame's. A
    /// frame found unstable is kept in `unstable` (the others still retire).
    pub fn settle(&mut self, ctx: &Context) -> Result<()> {
        loop {
            match self.frames.drain(ctx, &mut self.work) {
                Err(Error::Unstable(m)) => {
                    self.unstable.get_or_insert(m);
                }
                r => return r,
            }
        }
    }

    /// Simulated seconds so far.
    pub fn sim_time(&self) -> f64 {
        self.work.stepper().sim_time
    }

    /// The newest picture (RGBA8, width, height).
    pub fn picture(&self) -> Option<(&[u8], u32, u32)> {
        let l = self.work.frames.latest.as_ref()?;
        Some((&l.0, l.1, l.2))
    }

    pub fn set_camera(&mut self, cam: Camera) {
        self.cam = cam;
        self.work.set_camera(&cam);
    }

    /// Simulated time per window frame: `speed` times the scene's frame time.
    pub fn set_speed(&mut self, speed: f64) {
        self.work.stepper_mut().frame_time = self.frame_time * speed;
    }

    /// Rebuild the view with `sw` as the user gives them (switches of the metaball,
    /// camera and frame groups; the scene's look applied again; the simulation goes on).
    /// Frames in flight finish first. The home camera those switches give.
    pub fn rebuild_view(&mut self, ctx: &Context, sw: &Switches) -> Result<Camera> {
        self.settle(ctx)?;
        ctx.wait_idle()?;
        let mut sw = crate::settings::with_look(&self.scene.look, sw);
        if sw.metaball.radius.is_none() {
            sw.metaball.radius = self.sw.metaball.radius;
        }
        let mut cam = self.cam;
        cam.aspect = sw.frame.width() as f32 / sw.frame.height() as f32;
        let n = self.work.particles();
        let show = self.work.show();
        let view = make_view(ctx, &self.scene, &sw, self.render, &cam, n, show)?;
        self.work.replace_view(ctx, view);
        self.home = scene_camera(&self.scene, &sw);
        self.sw = sw;
        self.cam = cam;
        Ok(self.home)
    }

    /// Control switches that change only per-frame values, applied from the next frame
    /// (the simulation goes on); false when they need a rebuilt scene.
    pub fn set_control(&mut self, sw: &Switches) -> Result<bool> {
        let sw = crate::settings::with_look(&self.scene.look, sw);
        let ok = self.work.set_control(&sw, &self.scene.fluid)?;
        if ok {
            self.sw.control = sw.control;
        }
        Ok(ok)
    }

    pub fn stats(&self, ctx: &Context) -> LiveStats {
        let (particles, sim_time, steps) = self.work.progress();
        LiveStats {
            particles,
            sim_time,
            steps,
            render: self.work.render_stats(),
            memory_bytes: ctx.memory_bytes().values().sum(),
            control: self.work.control_rows(),
        }
    }

    /// The timeline's events as (time, what).
    pub fn events(&self) -> Vec<(f32, String)> {
        self.work.events()
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let _ = self.settle(ctx);
        self.frames.destroy(ctx);
        self.work.destroy(ctx);
    }
}
