//! `run` of the orbits test scene: a gravity step and the point view per frame.
use super::*;
use crate::gpu::Open;
use crate::orbits::{self, Orbits, OrbitsPass};

/// The orbits scene: a gravity step and the point view per frame.
struct OrbitsWork {
    pass: OrbitsPass,
    view: PointsViewer,
    scene: Orbits,
    frames: Frames,
}

impl FrameWork for OrbitsWork {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        {
            let _scope = prof.open(ctx, cmd, crate::orbits::SIMULATE.scope());
            self.pass.step(ctx, cmd, &self.scene, 1.0 / 120.0);
        }
        // New positions -> the point view's vertex shader.
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

impl OrbitsWork {
    fn destroy(&mut self, ctx: &Context) {
        self.scene.destroy(ctx);
        self.view.destroy(ctx);
        self.pass.destroy(ctx);
    }
}

pub(super) fn run_orbits(opts: &RunOptions) -> Result<RunResult> {
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
        frames: Frames::new(&opts.out, opts.save_every, frame_count).sampled(&sw.frame),
    };
    let memory = ctx.memory_bytes();
    let timings = play_run(&ctx, frame_count, &mut work, &opts.scene, &sw.common);
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
