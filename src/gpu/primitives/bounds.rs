//! Axis-aligned bounding box of vec4 positions by a two-level min/max reduction;
//! the result (min, max as two vec4) stays on the GPU for the Morton pass.
use crate::error::Result;
use crate::{Buffer, ComputePipeline, Context, Guard};
use ash::vk;
use bytemuck::{Pod, Zeroable};

const WG: u32 = 256;
const ITEMS: u32 = 8;
const BLOCK: u64 = (WG * ITEMS) as u64;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct BoundsPush {
    pub n: u32,
    pub pairs: u32,
}
const _: () = assert!(std::mem::size_of::<BoundsPush>() == 8);

crate::gpu_interface! {
    /// glsl/primitives/bounds.comp
    pub BoundsIo / BoundsBufs: "BOUNDS", push BoundsPush { src = 0, dst = 1 }
}

crate::compute_pass!(
    /// Both levels of the reduction (`pairs` says which input it reads).
    pub BOUNDS: BoundsIo, () = "bounds", "primitives/bounds.comp"
);

pub struct BoundsPass {
    pipeline: ComputePipeline<BoundsIo>,
}

/// Partial (min, max) pairs for up to `capacity` positions, and the final box.
pub struct BoundsBuffers {
    partials: Buffer,
    /// Two vec4: min (xyz), max (xyz).
    pub result: Buffer,
    capacity: u64,
}

impl BoundsBuffers {
    /// Bytes of its buffers.
    pub fn bytes(&self) -> u64 {
        self.partials.size + self.result.size
    }

    pub fn new(ctx: &Context, capacity: u64) -> Result<Self> {
        let partials = Guard::new(
            ctx,
            ctx.storage_buffer("bounds partials", capacity.div_ceil(BLOCK).max(1) * 32)?,
        );
        let result = ctx.storage_buffer("bounds", 32)?;
        Ok(Self {
            partials: partials.take(),
            result,
            capacity,
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_buffer(&mut self.partials);
        ctx.destroy_buffer(&mut self.result);
    }
}

impl BoundsPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: BOUNDS.pipeline(ctx, &(), WG, &[ITEMS])?,
        })
    }

    /// Record the box of the first `n` positions into `b.result`. Empty input gives
    /// min = +3.4e38, max = -3.4e38.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pos: &Buffer,
        n: u64,
        b: &BoundsBuffers,
    ) -> Result<()> {
        if n > b.capacity {
            return Err(crate::Error::Param(format!(
                "bounds of {n} positions exceed capacity {}",
                b.capacity
            )));
        }
        let groups = n.div_ceil(BLOCK);
        let push = BoundsPush {
            n: n as u32,
            pairs: 0,
        };
        let bufs = BoundsBufs {
            src: pos,
            dst: &b.partials,
        };
        self.pipeline
            .dispatch_groups(ctx, cmd, &bufs, &push, groups);
        let push = BoundsPush {
            n: groups as u32,
            pairs: 1,
        };
        let bufs = BoundsBufs {
            src: &b.partials,
            dst: &b.result,
        };
        self.pipeline.dispatch_groups(ctx, cmd, &bufs, &push, 1);
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
