//! Frames in flight: one command buffer, fence and timestamp pools per slot. Frame f waits
//! only for frame f - slots, reads that frame's timestamps and retires it. The work of a
//! frame is one `FrameWork` owner, driven by `record` and `retire` with `&mut self`.
use super::profiler::Profiler;
use super::{sync, Context};
use crate::error::{Result, VkContext};
use ash::vk;

/// What a run does each frame: record it, then retire it once its fence has signalled
/// (its timestamps already collected), before its slot is reused.
pub trait FrameWork {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()>;
    fn retire(&mut self, ctx: &Context, frame: u64, slot: usize) -> Result<()>;
}

/// Frames that only record (benchmarks): `F(prof, cmd)` per frame, nothing to retire.
pub struct RecordOnly<F>(pub F);

impl<F> FrameWork for RecordOnly<F>
where
    F: FnMut(&mut Profiler, vk::CommandBuffer) -> Result<()>,
{
    fn record(
        &mut self,
        _: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        _: u64,
        _: usize,
    ) -> Result<()> {
        (self.0)(prof, cmd)
    }
    fn retire(&mut self, _: &Context, _: u64, _: usize) -> Result<()> {
        Ok(())
    }
}

pub struct FrameLoop {
    pool: vk::CommandPool,
    slots: Vec<(vk::CommandBuffer, vk::Fence, Option<u64>)>,
    pub profiler: Profiler,
}

impl FrameLoop {
    pub fn new(ctx: &Context, slots: usize) -> Result<Self> {
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool = unsafe { ctx.device.create_command_pool(&info, None) }.ctx("frame pool")?;
        ctx.count_object("command pool", 1);
        ctx.set_name(pool, "frame command pool");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(slots as u32);
        let mut me = Self {
            pool,
            slots: Vec::new(),
            profiler: Profiler::new(ctx, 0)?,
        };
        // Everything made so far is released if a later step fails.
        let rest = (|| -> Result<()> {
            let cmds =
                unsafe { ctx.device.allocate_command_buffers(&alloc) }.ctx("frame commands")?;
            for (i, cmd) in cmds.into_iter().enumerate() {
                let fence = unsafe {
                    ctx.device
                        .create_fence(&vk::FenceCreateInfo::default(), None)
                }
                .ctx("frame fence")?;
                ctx.count_object("fence", 1);
                ctx.set_name(cmd, &format!("frame slot {i}"));
                ctx.set_name(fence, &format!("frame fence {i}"));
                me.slots.push((cmd, fence, None));
            }
            me.profiler = Profiler::new(ctx, slots)?;
            Ok(())
        })();
        match rest {
            Ok(()) => Ok(me),
            Err(e) => {
                me.destroy(ctx);
                Err(e)
            }
        }
    }

    /// Record, submit and retire `frames` frames of `work`.
    pub fn run(&mut self, ctx: &Context, frames: u64, work: &mut dyn FrameWork) -> Result<()> {
        for frame in 0..frames {
            self.step(ctx, frame, work)?;
        }
        self.drain(ctx, work)
    }

    /// Frame `frame` of `work`: retire the frame that last used its slot, then record and
    /// submit it. `run` plays frames 0.. with it; the viewer one per window frame.
    pub fn step(&mut self, ctx: &Context, frame: u64, work: &mut dyn FrameWork) -> Result<()> {
        let slot = (frame % self.slots.len() as u64) as usize;
        self.retire(ctx, slot, work)?;
        let cpu_begin = super::clock::monotonic_ns();
        let (cmd, fence, _) = self.slots[slot];
        unsafe {
            ctx.device
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .ctx("reset frame command")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            ctx.device
                .begin_command_buffer(cmd, &begin)
                .ctx("begin frame")?;
        }
        ctx.trackers.lock().unwrap().begin(cmd);
        // Frame boundary: the previous frames' writes are visible to this one's passes,
        // so a frame's work needs no barrier before its first reads.
        ctx.barrier(
            cmd,
            sync::COMPUTE_WRITE | sync::TRANSFER_WRITE | sync::FRAGMENT_WRITE,
            sync::COMPUTE_READ | sync::TRANSFER_READ | sync::GRAPHICS_READ | sync::INDIRECT_READ,
        );
        self.profiler.begin_frame(ctx, cmd, slot, frame);
        let recorded = work.record(ctx, cmd, &mut self.profiler, frame, slot);
        self.profiler.end_frame(ctx, cmd);
        unsafe { ctx.device.end_command_buffer(cmd) }.ctx("end frame")?;
        if let Err(e) = recorded {
            self.profiler.forget(slot);
            return Err(e);
        }
        ctx.submit(cmd, fence)?;
        self.profiler
            .note_cpu(slot, cpu_begin, super::clock::monotonic_ns());
        self.slots[slot].2 = Some(frame);
        Ok(())
    }

    /// Retire every frame still in flight, oldest first.
    pub fn drain(&mut self, ctx: &Context, work: &mut dyn FrameWork) -> Result<()> {
        let mut pending: Vec<(u64, usize)> = (self.slots.iter().enumerate())
            .filter_map(|(i, s)| s.2.map(|f| (f, i)))
            .collect();
        pending.sort();
        for (_, slot) in pending {
            self.retire(ctx, slot, work)?;
        }
        Ok(())
    }

    fn retire(&mut self, ctx: &Context, slot: usize, work: &mut dyn FrameWork) -> Result<()> {
        let (_, fence, pending) = self.slots[slot];
        if let Some(frame) = pending {
            ctx.wait(fence)?;
            unsafe { ctx.device.reset_fences(&[fence]) }.ctx("reset fence")?;
            self.slots[slot].2 = None;
            self.profiler.collect(ctx, slot)?;
            work.retire(ctx, frame, slot)?;
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            let _ = ctx.device.device_wait_idle();
            for (_, fence, _) in self.slots.drain(..) {
                ctx.device.destroy_fence(fence, None);
                ctx.count_object("fence", -1);
            }
            ctx.device.destroy_command_pool(self.pool, None);
            ctx.count_object("command pool", -1);
        }
        self.profiler.destroy(ctx);
    }
}
