//! 30-bit Morton codes (10 bits per axis) of positions relative to a GPU-side box.
use crate::error::Result;
use crate::{Buffer, ComputePipeline, Context};
use ash::vk;

crate::gpu_interface! {
    /// glsl/primitives/morton.comp; push: n.
    pub MortonIo / MortonBufs: "MORTON", push u32 { pos = 0, bounds = 1, keys = 2, vals = 3 }
}

crate::compute_pass!(pub MORTON: MortonIo, () = "morton", "primitives/morton.comp");

pub struct MortonPass {
    pipeline: ComputePipeline<MortonIo>,
}

impl MortonPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: MORTON.pipeline(ctx, &(), 256, &[])?,
        })
    }

    /// `keys[i]` = Morton code of `pos[i]` in `bounds` (two vec4), `vals[i] = i`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pos: &Buffer,
        bounds: &Buffer,
        keys: &Buffer,
        vals: &Buffer,
        n: u32,
    ) {
        let bufs = MortonBufs {
            pos,
            bounds,
            keys,
            vals,
        };
        self.pipeline.dispatch(ctx, cmd, &bufs, &n, n as u64);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}

/// CPU Morton code: the same quantisation as glsl/primitives/morton.glsl.
pub fn morton_code(q: [u32; 3]) -> u32 {
    fn expand(v: u32) -> u32 {
        let mut v = v & 0x3ff;
        v = (v | (v << 16)) & 0x0300_00ff;
        v = (v | (v << 8)) & 0x0300_f00f;
        v = (v | (v << 4)) & 0x030c_30c3;
        v = (v | (v << 2)) & 0x0924_9249;
        v
    }
    (expand(q[0]) << 2) | (expand(q[1]) << 1) | expand(q[2])
}

/// Lattice coordinate along one axis, in f64 (the test's reference).
pub fn morton_axis(p: f32, lo: f32, hi: f32) -> f64 {
    let ext = ((hi - lo) as f64).max(1e-30);
    ((p as f64 - lo as f64) / ext * 1024.0).clamp(0.0, 1023.0)
}
