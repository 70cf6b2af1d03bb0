//! Emit (seed 002, Algorithm 1; scope `emit`): one invocation per particle slot respawns
//! the slots past their life limit at random covered texels of the UV position buffers,
//! between the last frame's surface and this frame's, with the surface's velocity times
//! the transfer rate (eq. 7); the others age. Births per step are capped by a budget
//! (the emission rate); the counts come back in `counts` (due slots, slots alive).
use super::uv::UvSurface;
use crate::error::{Error, Result};
use crate::gpu::{sync, Buffer, ComputeDesc, ComputePipeline, Context, Guard, Scopes};
use ash::vk;
use bytemuck::{Pod, Zeroable};

/// glsl/emission/emit.comp `EmitParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct EmitGpuParams {
    pub n: u32,
    pub valid_count: u32,
    pub budget: u32,
    pub seed: u32,
    pub limit: f32,
    pub dt: f32,
    pub dtau: f32,
    pub k: f32,
}
const _: () = assert!(std::mem::size_of::<EmitGpuParams>() == 32);

crate::gpu_interface! {
    /// glsl/emission/emit.comp
    pub EmitIo / EmitBufs: "EMIT", push () {
        params = 0, cur = 1, prev = 2, valid = 3, pos = 4, vel = 5, life = 6, counts = 7,
    }
}

/// The emitter's switches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitSettings {
    /// Life limit in seconds.
    pub limit: f32,
    /// Births per step at most.
    pub budget: u32,
    /// k times the frame time: 1 gives particles the surface's own velocity.
    pub transfer: f32,
    /// Half the finite-difference interval in tau (0 < dtau < 1/2).
    pub dtau: f32,
}

impl EmitSettings {
    pub fn validate(&self) -> Result<()> {
        if !(self.limit.is_finite() && self.limit > 0.0) {
            return Err(Error::Param(format!(
                "--life-limit must be positive, got {}",
                self.limit
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

pub struct EmitPass {
    pipeline: ComputePipeline<EmitIo>,
    params: Buffer,
    /// uvec4: due slots, slots alive (reset each step).
    pub counts: Buffer,
}

impl EmitPass {
    pub const NAME: &'static str = "emit";

    pub fn new(ctx: &Context) -> Result<Self> {
        let d = ComputeDesc::plain("emit", "emission/emit.comp", &[], 64);
        let pipeline = Guard::new(ctx, ComputePipeline::new(ctx, &d)?);
        let params = Guard::new(
            ctx,
            ctx.storage_buffer("emit params", std::mem::size_of::<EmitGpuParams>() as u64)?,
        );
        let counts = ctx.storage_buffer("emit counts", 16)?;
        Ok(Self {
            pipeline: pipeline.take(),
            params: params.take(),
            counts,
        })
    }

    /// Record one step of `dt` seconds over `n` slots (`pos`, `vel`: vec4; `life`: f32),
    /// emitting from `uv`'s last two frames (`frame_dt` seconds apart); `step` seeds the
    /// draws.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        uv: &UvSurface,
        (pos, vel, life): (&Buffer, &Buffer, &Buffer),
        n: u32,
        s: &EmitSettings,
        (dt, frame_dt): (f32, f32),
        step: u64,
    ) -> Result<()> {
        s.validate()?;
        let seed = (step ^ (step >> 32)) as u32;
        let p = EmitGpuParams {
            n,
            valid_count: uv.valid_count,
            budget: s.budget,
            seed: seed.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B,
            limit: s.limit,
            dt,
            dtau: s.dtau,
            k: if frame_dt > 0.0 {
                s.transfer / frame_dt
            } else {
                0.0
            },
        };
        scopes.begin(ctx, cmd, Self::NAME);
        ctx.barrier(
            cmd,
            sync::COMPUTE_READ | sync::TRANSFER_READ,
            sync::TRANSFER_WRITE,
        );
        ctx.update(cmd, &self.params, 0, &[p]);
        ctx.fill(cmd, &self.counts, 0);
        ctx.barrier(cmd, sync::TRANSFER_WRITE, sync::COMPUTE_READ);
        let c = uv.current();
        let bufs = EmitBufs {
            params: &self.params,
            cur: &uv.pos[c],
            prev: &uv.pos[1 - c],
            valid: &uv.valid,
            pos,
            vel,
            life,
            counts: &self.counts,
        };
        self.pipeline.dispatch(ctx, cmd, &bufs, &(), n as u64);
        ctx.barrier(
            cmd,
            sync::COMPUTE_WRITE,
            sync::COMPUTE_READ | sync::TRANSFER_READ,
        );
        scopes.end(ctx, cmd);
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        ctx.destroy_buffer(&mut self.params);
        ctx.destroy_buffer(&mut self.counts);
    }
}
crate::impl_destroy!(EmitPass);
