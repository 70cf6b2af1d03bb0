//! Emit (seed 002, Algorithm 1; scope `emit`): one invocation per particle slot ages the
//! live slots and gives the due ones (past their life limit, or dead) a birth at a random
//! source point between the last two frames of the surface, with the surface's velocity
//! times the transfer rate (eq. 7), while the step's budget lasts; the rest die. Counts per
//! step (due, alive, birth requests), per frame (births, speeds) and per emitting
//! primitive (births) stay on the GPU.
use crate::error::{Error, Result};
use crate::gpu::pass::{Defines, PassKey};
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard};
use bytemuck::{Pod, Zeroable};

/// glsl/emission/emit.comp `EmitParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct EmitGpuParams {
    pub n: u32,
    pub sources: u32,
    pub budget: u32,
    pub seed: u32,
    pub limit: f32,
    pub dt: f32,
    pub dtau: f32,
    pub k: f32,
    pub tau_lo: f32,
    pub tau_hi: f32,
    pub frame_dt: f32,
    /// Births are moved this far (metres) in a random direction: two births at one
    /// source on a still surface would otherwise coincide, and SPH cannot part them.
    pub jitter: f32,
}
const _: () = assert!(std::mem::size_of::<EmitGpuParams>() == 48);

crate::gpu_interface! {
    /// glsl/emission/emit.comp
    pub EmitIo / EmitBufs: "EMIT", push () {
        params = 0, cur = 1, prev = 2, valid = 3, pos = 4, vel = 5, vhalf = 6, life = 7,
        counts = 8, stats = 9, hist = 10,
    }
}

/// The emitter's switches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitSettings {
    /// Life limit in seconds.
    pub limit: f32,
    /// Births per second at most (None: every due slot is born, as in Algorithm 1).
    pub rate: Option<f32>,
    /// k times the frame time: 1 gives particles the surface's own velocity.
    pub transfer: f32,
    /// Half the finite-difference interval in tau (0 < dtau < 1/2).
    pub dtau: f32,
}

/// Whether the emitter's sources are UV-layout texels (else mesh vertices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FromTexels(pub bool);

impl PassKey for FromTexels {
    fn all() -> Vec<Self> {
        vec![Self(false), Self(true)]
    }
    fn defines(&self) -> Defines {
        vec![("EMIT_UV".to_string(), (self.0 as u32).to_string())]
    }
}

crate::gpu::compute_pass!(pub EMIT: EmitIo, FromTexels = "emit", "emission/emit.comp");

impl Default for EmitSettings {
    fn default() -> Self {
        Self {
            limit: 2.0,
            rate: None,
            transfer: 1.0,
            dtau: 0.05,
        }
    }
}

impl EmitSettings {
    pub fn validate(&self) -> Result<()> {
        if !(self.limit.is_finite() && self.limit > 0.0) {
            return Err(Error::Param(format!(
                "--life-limit must be positive, got {}",
                self.limit
            )));
        }
        if let Some(r) = self.rate.filter(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(Error::Param(format!(
                "--emission-rate must be positive, got {r}"
            )));
        }
        if !(self.transfer.is_finite() && self.transfer >= 0.0) {
            return Err(Error::Param(format!(
                "--transfer must be at least 0, got {}",
                self.transfer
            )));
        }
        if !(self.dtau > 0.0 && self.dtau < 0.5) {
            return Err(Error::Param(format!(
                "dtau must be in (0, 0.5), got {}",
                self.dtau
            )));
        }
        Ok(())
    }
}

/// One step's emission: the source's two frames and list, the particle buffers.
pub struct EmitInput<'a> {
    pub cur: &'a Buffer,
    pub prev: &'a Buffer,
    pub valid: &'a Buffer,
    pub sources: u32,
    pub pos: &'a Buffer,
    pub vel: &'a Buffer,
    pub vhalf: &'a Buffer,
    pub life: &'a Buffer,
}

pub struct EmitPass {
    pipeline: ComputePipeline<EmitIo>,
    params: Buffer,
    /// uvec4 per step: due slots, slots alive, birth requests.
    pub counts: Buffer,
    /// uvec4 since cleared: births, summed birth speed, summed surface speed (cm/s).
    pub stats: Buffer,
    /// Births per emitting primitive (layout triangle or vertex).
    pub hist: Buffer,
    pub primitives: u32,
}

impl EmitPass {
    /// Byte offset of the alive count in `counts`.
    pub const ALIVE_OFFSET: u64 = 4;

    /// For an emitter over `primitives` histogram bins; `uv`: the sources are texels whose
    /// w holds the layout triangle + 1 (else vertices, binned by index).
    pub fn new(ctx: &Context, uv: bool, primitives: u32) -> Result<Self> {
        let pipeline = Guard::new(ctx, EMIT.pipeline(ctx, &FromTexels(uv), 64, &[])?);
        let buf = |name: &str, bytes| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let params = buf("emit params", std::mem::size_of::<EmitGpuParams>() as u64)?;
        let counts = buf("emit counts", 16)?;
        let stats = buf("emit stats", 16)?;
        let hist = buf("emit histogram", primitives.max(1) as u64 * 4)?;
        let s = Self {
            pipeline: pipeline.take(),
            params: params.take(),
            counts: counts.take(),
            stats: stats.take(),
            hist: hist.take(),
            primitives,
        };
        let s = Guard::new(ctx, s);
        ctx.one_shot(|cmd| s.record_clear(ctx, cmd))?;
        Ok(s.take())
    }

    /// Zero the per-frame stats and the histogram.
    pub fn record_clear(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.fill(cmd, &self.stats, 0);
        ctx.fill(cmd, &self.hist, 0);
    }

    /// Zero the per-frame stats (after the frame's copy of them).
    pub fn record_clear_stats(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.fill(cmd, &self.stats, 0);
    }

    /// Record one step over `p.n` slots (in the caller's scope).
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        p: &EmitGpuParams,
        input: &EmitInput,
    ) {
        ctx.update(cmd, &self.params, 0, &[*p]);
        ctx.fill(cmd, &self.counts, 0);
        let bufs = EmitBufs {
            params: &self.params,
            cur: input.cur,
            prev: input.prev,
            valid: input.valid,
            pos: input.pos,
            vel: input.vel,
            vhalf: input.vhalf,
            life: input.life,
            counts: &self.counts,
            stats: &self.stats,
            hist: &self.hist,
        };
        self.pipeline.dispatch(ctx, cmd, &bufs, &(), p.n as u64);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        for b in [
            &mut self.params,
            &mut self.counts,
            &mut self.stats,
            &mut self.hist,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(EmitPass);
