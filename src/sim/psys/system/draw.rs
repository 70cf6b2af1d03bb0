//! A particle system's depth sort (odd-even, bitonic or counting, by view depth) and its
//! indirect draw.
use super::*;
use crate::gpu::Open;

impl ParticleSystem {
    /// The sorted slots (NO_SLOT past the drawn ones) and their keys after `record_sort`.
    pub fn read_sorted(&self, ctx: &Context) -> Result<(Vec<u32>, Vec<u32>)> {
        let cap = self.capacity as usize;
        match &self.counting {
            Some(d) => Ok((
                ctx.readback(&d.keys, 0, cap)?,
                ctx.readback(&d.vals, 0, cap)?,
            )),
            None => Ok((
                ctx.readback(&self.keys, 0, cap)?,
                ctx.readback(&self.vals, 0, cap)?,
            )),
        }
    }

    /// Record the draw's vertex count from the list that is drawn (after spawns into it).
    pub fn record_draw_count(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        passes: &Passes,
        f: &FrameInfo,
    ) {
        let mut push = self.push(f, f.time, 0);
        push.cur = 1 - self.drawn;
        push.mode = 1;
        passes
            .args
            .dispatch_groups(ctx, cmd, &self.bufs(passes, f), &push, 1);
    }

    /// Record the depth sort of what is drawn (nothing with --sort none). The step's
    /// writes must be visible to compute.
    pub fn record_sort(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        passes: &Passes,
        f: &FrameInfo,
    ) -> Result<()> {
        if self.sort == SortAlgo::None {
            return Ok(());
        }
        let t = f.time + f.dt as f64;
        let mut push = self.push(f, t, 0);
        // Keys read the list the step wrote: the shader reads alive[1 - cur].
        push.cur = 1 - self.drawn;
        push.mode = (self.sort == SortAlgo::Counting) as u32;
        let bufs = self.bufs(passes, f);
        let cap = self.capacity as u64;
        {
            let _scope = scopes.open(ctx, cmd, Passes::SORT);
            if self.closed() {
                let zero = StepPush { mode: 2, ..push };
                passes.args.dispatch_groups(ctx, cmd, &bufs, &zero, 1);
            }
            passes.keys.dispatch(ctx, cmd, &bufs, &push, cap);
            match (self.sort, &self.counting) {
                (SortAlgo::Counting, Some(d)) => {
                    passes.counting.record(
                        ctx,
                        cmd,
                        &passes.scan,
                        &d.cells,
                        &self.keys,
                        &self.vals,
                        &d.keys,
                        &d.vals,
                        cap,
                    )?;
                }
                (SortAlgo::OddEven, _) => {
                    passes
                        .odd_even
                        .record(ctx, cmd, &self.keys, &self.vals, cap)?;
                }
                (SortAlgo::Bitonic, _) => {
                    passes
                        .bitonic
                        .record(ctx, cmd, &self.keys, &self.vals, cap)?;
                }
                _ => unreachable!("counting buffers exist for the counting sort"),
            }
        }
        Ok(())
    }

    /// The draw's buffers, push constants and whether it draws every slot (1) or the
    /// count a pass wrote (0).
    fn draw_setup(&self, f: &FrameInfo) -> (DrawBufs<'_>, DrawPush, u32) {
        let (r, u) = f.cam.axes();
        let t = (f.time + f.dt as f64) as f32;
        let (order, offset, identity) = match (self.sort, &self.counting) {
            (SortAlgo::None, _) if self.closed() => (&self.alive, 0, 1),
            (SortAlgo::None, _) => (&self.alive, self.drawn * self.capacity, 0),
            (SortAlgo::Counting, Some(d)) => (&d.vals, 0, 0),
            _ => (&self.vals, 0, 0),
        };
        let push = DrawPush {
            view_proj: f.cam.view_proj().to_cols_array_2d(),
            right: [r.x, r.y, r.z, self.spec.point_px],
            up: [u.x, u.y, u.z, t],
            screen: [
                2.0 / f.width as f32,
                2.0 / f.height as f32,
                f.dt,
                self.sprite_side as f32,
            ],
            offset,
            identity,
            pad: [0; 2],
        };
        let bufs = DrawBufs {
            params: &self.params,
            pos: &self.pos,
            vel: &self.vel,
            prev: &self.prev,
            color: &self.color,
            order,
            sprite: &self.sprite,
        };
        (bufs, push, identity)
    }

    /// Declare this system's draw in the next rendering scope (before it begins).
    pub fn prepare_draw(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        passes: &Passes,
        f: &FrameInfo,
    ) {
        let (bufs, _, identity) = self.draw_setup(f);
        passes.pipeline(self.mode).prepare(ctx, cmd, &bufs);
        if identity == 0 {
            ctx.prepare_draws(
                cmd,
                &[crate::gpu::track::BufferUse::indirect(self.counters.raw)],
            );
        }
    }

    /// Record the draw (inside a rendering scope declared by `prepare_draw`).
    pub fn record_draw(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        passes: &Passes,
        f: &FrameInfo,
    ) {
        let (bufs, push, identity) = self.draw_setup(f);
        passes.pipeline(self.mode).bind(ctx, cmd, &bufs, &push);
        if identity == 1 {
            ctx.draw(cmd, vertices(self.mode) * self.capacity, 1);
        } else {
            ctx.draw_indirect(cmd, &self.counters, Counters::DRAW_ARGS);
        }
    }
}

/// The counting sort's cells and its sorted copies of the keys and values.
pub(super) struct DepthSort {
    pub(super) cells: CountingBuffers,
    pub(super) keys: Buffer,
    pub(super) vals: Buffer,
}

impl DepthSort {
    pub(super) fn new(ctx: &Context, passes: &Passes, name: &str, cap: u64) -> Result<Self> {
        let cells = Guard::new(
            ctx,
            CountingBuffers::new(ctx, &passes.scan, cap, DEPTH_CELLS)?,
        );
        let buf = |what: &str| {
            ctx.storage_buffer(&format!("{name} sorted {what}"), cap * 4)
                .map(|b| Guard::new(ctx, b))
        };
        let (keys, vals) = (buf("keys")?, buf("values")?);
        Ok(Self {
            cells: cells.take(),
            keys: keys.take(),
            vals: vals.take(),
        })
    }

    pub(super) fn destroy(&mut self, ctx: &Context) {
        self.cells.destroy(ctx);
        ctx.destroy_buffer(&mut self.keys);
        ctx.destroy_buffer(&mut self.vals);
    }
}
crate::impl_destroy!(DepthSort);
