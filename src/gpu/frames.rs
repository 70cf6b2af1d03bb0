//! Frames in flight: one command buffer, fence and timestamp pool per slot. Frame f waits
//! only for frame f - slots, reads that frame's timestamps and hands it to `done`.
use super::profiler::Profiler;
use super::Context;
use crate::error::{Result, VkContext};
use ash::vk;

pub struct FrameLoop {
    pool: vk::CommandPool,
    slots: Vec<(vk::CommandBuffer, vk::Fence, Option<u64>)>,
    pub profiler: Profiler,
}

impl FrameLoop {
    pub fn new(ctx: &Context, slots: usize, max_scopes: u32) -> Result<Self> {
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool = unsafe { ctx.device.create_command_pool(&info, None) }.ctx("frame pool")?;
        ctx.set_name(pool, "frame command pool");
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(slots as u32);
        let cmds = unsafe { ctx.device.allocate_command_buffers(&alloc) }.ctx("frame commands")?;
        let mut v = Vec::new();
        for (i, cmd) in cmds.into_iter().enumerate() {
            let fence = unsafe {
                ctx.device
                    .create_fence(&vk::FenceCreateInfo::default(), None)
            }
            .ctx("frame fence")?;
            ctx.set_name(cmd, &format!("frame slot {i}"));
            ctx.set_name(fence, &format!("frame fence {i}"));
            v.push((cmd, fence, None));
        }
        Ok(Self {
            pool,
            slots: v,
            profiler: Profiler::new(ctx, slots, max_scopes)?,
        })
    }

    /// Record and submit `frames` frames; `done(frame, slot)` runs once a frame's fence
    /// signalled (its timestamps already collected), before its slot is reused.
    pub fn run(
        &mut self,
        ctx: &Context,
        frames: u64,
        mut record: impl FnMut(&mut Profiler, vk::CommandBuffer, u64, usize) -> Result<()>,
        mut done: impl FnMut(u64, usize) -> Result<()>,
    ) -> Result<()> {
        for frame in 0..frames {
            let slot = (frame % self.slots.len() as u64) as usize;
            self.retire(ctx, slot, &mut done)?;
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
            self.profiler.begin_frame(ctx, cmd, slot, frame);
            let recorded = record(&mut self.profiler, cmd, frame, slot);
            self.profiler.end_frame(ctx, cmd);
            unsafe { ctx.device.end_command_buffer(cmd) }.ctx("end frame")?;
            if let Err(e) = recorded {
                self.profiler.forget(slot);
                return Err(e);
            }
            ctx.submit(cmd, fence)?;
            self.slots[slot].2 = Some(frame);
        }
        for slot in 0..self.slots.len() {
            let next = (frames as usize + slot) % self.slots.len();
            self.retire(ctx, next, &mut done)?;
        }
        Ok(())
    }

    fn retire(
        &mut self,
        ctx: &Context,
        slot: usize,
        done: &mut impl FnMut(u64, usize) -> Result<()>,
    ) -> Result<()> {
        let (_, fence, pending) = self.slots[slot];
        if let Some(frame) = pending {
            ctx.wait(fence)?;
            unsafe { ctx.device.reset_fences(&[fence]) }.ctx("reset fence")?;
            self.slots[slot].2 = None;
            self.profiler.collect(ctx, slot)?;
            done(frame, slot)?;
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            let _ = ctx.device.device_wait_idle();
            for (_, fence, _) in self.slots.drain(..) {
                ctx.device.destroy_fence(fence, None);
            }
            ctx.device.destroy_command_pool(self.pool, None);
        }
        self.profiler.destroy(ctx);
    }
}
