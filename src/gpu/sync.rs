//! Barriers, placed by the tracker (`gpu::track`) from what each command reads and writes:
//! a dispatch, copy, fill or update through the context gets the barrier its buffers'
//! hazards need, and code that sequences compute and transfer work places none by hand.
//! By hand, each with a comment naming what it protects, remain only what the tracker
//! cannot see or may not place: buffers a draw reads or writes (no barrier may be recorded
//! inside a rendering scope, so they go before it; the tracker counts any it finds
//! uncovered), images, host reads after the fence, the frame boundary, and the profiler's
//! settle.
use super::track::BufferUse;
use super::Context;
use ash::vk;
use std::ops::BitOr;

/// One side of a dependency: pipeline stages and the memory accesses in them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Access {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
}

impl BitOr for Access {
    type Output = Access;
    fn bitor(self, o: Access) -> Access {
        Access {
            stage: self.stage | o.stage,
            access: self.access | o.access,
        }
    }
}

const fn acc(stage: vk::PipelineStageFlags2, access: vk::AccessFlags2) -> Access {
    Access { stage, access }
}

/// Storage writes of compute shaders.
pub const COMPUTE_WRITE: Access = acc(
    vk::PipelineStageFlags2::COMPUTE_SHADER,
    vk::AccessFlags2::SHADER_STORAGE_WRITE,
);
/// Storage reads of compute shaders (and their writes, ordered after earlier writes).
pub const COMPUTE_READ: Access = acc(
    vk::PipelineStageFlags2::COMPUTE_SHADER,
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
            | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
    ),
);
/// Copies, fills and updates writing a buffer.
pub const TRANSFER_WRITE: Access = acc(
    vk::PipelineStageFlags2::ALL_TRANSFER,
    vk::AccessFlags2::TRANSFER_WRITE,
);
/// Copies reading a buffer (and transfer writes ordered after earlier writes).
pub const TRANSFER_READ: Access = acc(
    vk::PipelineStageFlags2::ALL_TRANSFER,
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::TRANSFER_READ.as_raw() | vk::AccessFlags2::TRANSFER_WRITE.as_raw(),
    ),
);
/// Storage writes of fragment shaders (per-pixel lists).
pub const FRAGMENT_WRITE: Access = acc(
    vk::PipelineStageFlags2::FRAGMENT_SHADER,
    vk::AccessFlags2::SHADER_STORAGE_WRITE,
);
/// Storage reads (and writes) of vertex and fragment shaders.
pub const GRAPHICS_READ: Access = acc(
    vk::PipelineStageFlags2::from_raw(
        vk::PipelineStageFlags2::VERTEX_SHADER.as_raw()
            | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw(),
    ),
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::SHADER_STORAGE_READ.as_raw()
            | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
    ),
);
/// Indirect dispatch and draw arguments.
pub const INDIRECT_READ: Access = acc(
    vk::PipelineStageFlags2::DRAW_INDIRECT,
    vk::AccessFlags2::INDIRECT_COMMAND_READ,
);
/// Colour and depth attachment writes of a draw.
pub const ATTACHMENT_WRITE: Access = acc(
    vk::PipelineStageFlags2::from_raw(
        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT.as_raw()
            | vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
            | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
    ),
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw()
            | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
    ),
);
/// Every stage and access: only for an execution stall that protects no data (the
/// profiler's timestamp settle on llvmpipe).
pub const ALL: Access = acc(
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::MEMORY_READ.as_raw() | vk::AccessFlags2::MEMORY_WRITE.as_raw(),
    ),
);
/// The host reading a mapped buffer after the fence.
pub const HOST_READ: Access = acc(vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ);

impl Context {
    /// A memory dependency from `from` (earlier commands) to `to` (later commands).
    pub fn barrier(&self, cmd: vk::CommandBuffer, from: Access, to: Access) {
        self.trackers.lock().unwrap().get(cmd).barrier(from, to);
        self.record_barrier(cmd, from, to);
    }

    /// A stall the profiler needs (every stage to every stage), not counted among the
    /// barriers `recorded` reports: instrumentation, not the work's own.
    pub fn profiler_stall(&self, cmd: vk::CommandBuffer) {
        self.trackers.lock().unwrap().get(cmd).barrier(ALL, ALL);
        self.record_barrier_uncounted(cmd, ALL, ALL);
    }

    /// Record the buffer uses of the next command (`gpu::track`); `place`: record the
    /// barrier it needs, if any (never inside a rendering scope).
    pub fn track(&self, cmd: vk::CommandBuffer, uses: &[BufferUse], place: bool) {
        self.track_as(cmd, uses, place, |t, u| t.before(u, place));
    }

    /// Declare the buffer uses of the next rendering scope's draws (before it begins):
    /// the barrier they need is recorded now.
    pub fn prepare_draws(&self, cmd: vk::CommandBuffer, uses: &[BufferUse]) {
        self.track_as(cmd, uses, true, |t, u| t.declare(u));
    }

    /// The host reads `buffers` (mapped) after this command buffer's fence: the barrier
    /// that makes the device's writes visible there.
    pub fn host_reads(&self, cmd: vk::CommandBuffer, buffers: &[&super::Buffer]) {
        let uses: Vec<BufferUse> = buffers.iter().map(|b| BufferUse::host(b.raw)).collect();
        self.track_as(cmd, &uses, true, |t, u| t.host_read(u));
    }

    fn track_as(
        &self,
        cmd: vk::CommandBuffer,
        uses: &[BufferUse],
        place: bool,
        how: impl FnOnce(&mut super::track::Tracker, &[BufferUse]) -> Option<(Access, Access)>,
    ) {
        let (need, debug) = {
            let mut t = self.trackers.lock().unwrap();
            let debug = t.debug;
            (how(t.get(cmd), uses), debug)
        };
        if need.is_some() && debug {
            let bt = std::backtrace::Backtrace::force_capture().to_string();
            let at: Vec<&str> = bt
                .lines()
                .filter(|l| l.contains("fluidform") && !l.contains("fluidform_gpu::"))
                .take(3)
                .collect();
            eprintln!("track: place={place} {need:?} at {}", at.join(" < "));
        }
        if let (Some((from, to)), true) = (need, place) {
            self.record_barrier(cmd, from, to);
        }
    }

    /// Barriers the tracker placed and hazards it could not place a barrier for (in draws),
    /// over the command buffers submitted so far.
    pub fn tracked_barriers(&self) -> (u64, u64) {
        let t = self.trackers.lock().unwrap();
        (t.placed, t.unplaced)
    }

    fn record_barrier(&self, cmd: vk::CommandBuffer, from: Access, to: Access) {
        self.trackers.lock().unwrap().get(cmd).recorded.barriers += 1;
        self.record_barrier_uncounted(cmd, from, to);
    }

    fn record_barrier_uncounted(&self, cmd: vk::CommandBuffer, from: Access, to: Access) {
        let b = [vk::MemoryBarrier2::default()
            .src_stage_mask(from.stage)
            .src_access_mask(from.access)
            .dst_stage_mask(to.stage)
            .dst_access_mask(to.access)];
        let dep = vk::DependencyInfo::default().memory_barriers(&b);
        unsafe { self.device.cmd_pipeline_barrier2(cmd, &dep) };
    }

    fn count_transfer(&self, cmd: vk::CommandBuffer) {
        self.trackers.lock().unwrap().get(cmd).recorded.transfers += 1;
    }

    /// A dispatch was recorded into `cmd` (`indirect`: its group counts on the device).
    pub(crate) fn count_dispatch(&self, cmd: vk::CommandBuffer, indirect: bool) {
        let mut t = self.trackers.lock().unwrap();
        let r = &mut t.get(cmd).recorded;
        r.dispatches += 1;
        r.indirect += indirect as u32;
    }

    /// The recording `cmd` is in: a command buffer begun again is another recording.
    pub fn recording(&self, cmd: vk::CommandBuffer) -> u64 {
        self.trackers.lock().unwrap().get(cmd).serial
    }

    /// The commands recorded into `cmd` so far (take two and subtract: a sequence's cost).
    pub fn recorded(&self, cmd: vk::CommandBuffer) -> super::track::Recorded {
        self.trackers.lock().unwrap().get(cmd).recorded
    }

    /// Compute writes visible to later compute reads and writes: the common case.
    pub fn compute_barrier(&self, cmd: vk::CommandBuffer) {
        self.barrier(cmd, COMPUTE_WRITE, COMPUTE_READ);
    }

    /// Copy `size` bytes from `src` at `src_offset` to `dst` at `dst_offset`.
    pub fn copy(
        &self,
        cmd: vk::CommandBuffer,
        src: &super::Buffer,
        src_offset: u64,
        dst: &super::Buffer,
        dst_offset: u64,
        size: u64,
    ) {
        let uses = [
            BufferUse::transfer(src.raw, false).bytes(src_offset, size),
            BufferUse::transfer(dst.raw, true).bytes(dst_offset, size),
        ];
        self.track(cmd, &uses, true);
        self.count_transfer(cmd);
        let region = vk::BufferCopy {
            src_offset,
            dst_offset,
            size,
        };
        unsafe {
            self.device
                .cmd_copy_buffer(cmd, src.raw, dst.raw, &[region])
        };
    }

    /// Fill the whole buffer with a u32 value.
    pub fn fill(&self, cmd: vk::CommandBuffer, b: &super::Buffer, value: u32) {
        self.track(cmd, &[BufferUse::transfer(b.raw, true)], true);
        self.count_transfer(cmd);
        unsafe {
            self.device
                .cmd_fill_buffer(cmd, b.raw, 0, vk::WHOLE_SIZE, value)
        };
    }

    /// Write `data` into `b` at byte `offset`, in command order: one vkCmdUpdateBuffer per
    /// 65536 bytes, the most one takes.
    pub fn update<T: bytemuck::Pod>(
        &self,
        cmd: vk::CommandBuffer,
        b: &super::Buffer,
        offset: u64,
        data: &[T],
    ) {
        const MOST: usize = 65536;
        let bytes: &[u8] = bytemuck::cast_slice(data);
        for (k, chunk) in bytes.chunks(MOST).enumerate() {
            let at = offset + (k * MOST) as u64;
            let u = BufferUse::transfer(b.raw, true).bytes(at, chunk.len() as u64);
            self.track(cmd, &[u], true);
            self.count_transfer(cmd);
            unsafe { self.device.cmd_update_buffer(cmd, b.raw, at, chunk) };
        }
    }

    /// Wait until the device is idle (before replacing buffers frames in flight use).
    pub fn wait_idle(&self) -> crate::error::Result<()> {
        use crate::error::VkContext;
        unsafe { self.device.device_wait_idle() }.ctx("wait for the device to be idle")
    }

    /// End a dynamic-rendering scope.
    pub fn end_rendering(&self, cmd: vk::CommandBuffer) {
        unsafe { self.device.cmd_end_rendering(cmd) };
        self.trackers.lock().unwrap().get(cmd).end_scope();
    }

    /// Non-indexed draw of `vertices` x `instances` (inside a rendering scope).
    pub fn draw(&self, cmd: vk::CommandBuffer, vertices: u32, instances: u32) {
        unsafe { self.device.cmd_draw(cmd, vertices, instances, 0, 0) };
    }

    /// One draw whose VkDrawIndirectCommand a GPU pass wrote into `args` at byte `offset`.
    pub fn draw_indirect(&self, cmd: vk::CommandBuffer, args: &super::Buffer, offset: u64) {
        self.track(cmd, &[BufferUse::indirect(args.raw)], false);
        unsafe { self.device.cmd_draw_indirect(cmd, args.raw, offset, 1, 16) };
    }

    /// `vertices` vertices from `first` (gl_VertexIndex counts from `first`), one instance.
    pub fn draw_range(&self, cmd: vk::CommandBuffer, vertices: u32, first: u32) {
        unsafe { self.device.cmd_draw(cmd, vertices, 1, first, 0) };
    }
}
