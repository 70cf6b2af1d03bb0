//! A rough floor for a frame on this device, measured in the same run as the frame: its
//! least memory traffic over the buffer-copy bandwidth, or its density evaluations over
//! the FMA rate, whichever is larger. `bench render` prints each row's floor and how far
//! above it the row is.
use super::protocol::{self, Case};
use super::BenchOptions;
use crate::error::Result;
use crate::gpu::Open;
use crate::gpu::{Context, Guard};
use serde_json::json;

/// The floor's timestamp scopes: a buffer copy and the FMA-rate kernel.
pub const COPY: crate::gpu::ScopeKey = crate::gpu::ScopeKey::new("copy");
pub const FMA: crate::gpu::ScopeKey = crate::gpu::ScopeKey::new("fma");

/// FLOPs of one density evaluation (Wyvill, from r^2 and the sum): d = x - c (3), r^2 (5),
/// q^2 (1), the cubic in q^2 by Horner (6), the sum (1).
pub const FLOPS_PER_EVAL: f64 = 16.0;

crate::gpu_interface! {
    /// glsl/bench/fma.comp; push: the iterations per invocation.
    pub FmaIo / FmaBufs: "FMA", push u32 { out = 0 }
}

crate::gpu::compute_pass!(
    /// FMA chains: the device's arithmetic rate (here), the protocol's sentinel (64 wide).
    pub FMA_PASS: FmaIo, () = "fma rate", "bench/fma.comp"
);

/// Iterations per invocation of fma.comp (64 FLOPs each), within llvmpipe's loop budget.
const ITERS: u32 = 512;

pub struct Floor {
    /// Bytes per second a buffer copy moves (read plus written).
    pub bytes_per_s: f64,
    pub flops_per_s: f64,
}

impl Floor {
    /// Measure both rates (median of the bench's repetitions).
    pub fn measure(ctx: &Context, opts: &BenchOptions) -> Result<Self> {
        let cpu = ctx.info.kind.to_lowercase().contains("cpu");
        // Enough work to time well: about a millisecond on a GPU, tens on lavapipe.
        let (bytes, invocations): (u64, u64) = match cpu {
            true => (32 << 20, 1 << 16),
            false => (512 << 20, 1 << 22),
        };
        let src = Guard::new(ctx, ctx.storage_buffer("floor copy source", bytes)?);
        let dst = Guard::new(ctx, ctx.storage_buffer("floor copy target", bytes)?);
        let out = Guard::new(ctx, ctx.storage_buffer("floor fma out", invocations * 16)?);
        let fma = Guard::new(ctx, FMA_PASS.pipeline(ctx, &(), 256, &[])?);
        // Its own folder: the table it serves writes rounds.csv of its own.
        let mut opts = opts.clone();
        opts.out = opts.out.join("floor");
        opts.switches.common.trace = None;
        let (src, dst, out) = (&*src, &*dst, &*out);
        let fma = &*fma;
        let cases = vec![
            Case::new("copy", bytes, COPY, json!({}), move |prof, cmd| {
                {
                    let _scope = prof.open(ctx, cmd, COPY.scope());
                    ctx.copy(cmd, src, 0, dst, 0, bytes);
                }
                Ok(())
            }),
            Case::new("fma", invocations, FMA, json!({}), move |prof, cmd| {
                {
                    let _scope = prof.open(ctx, cmd, FMA.scope());
                    fma.dispatch(ctx, cmd, &FmaBufs { out }, &ITERS, invocations);
                }
                Ok(())
            }),
        ];
        let rows = protocol::run(ctx, &opts, cases)?;
        let (copy, rate) = (&rows[0], &rows[1]);
        let flops = invocations as f64 * ITERS as f64 * 64.0;
        let floor = Self {
            bytes_per_s: 2.0 * bytes as f64 / (copy.main.median / 1e3),
            flops_per_s: flops / (rate.main.median / 1e3),
        };
        eprintln!(
            "floor rates: copy {:.1} GB/s (read + written), FMA {:.1} GFLOP/s",
            floor.bytes_per_s / 1e9,
            floor.flops_per_s / 1e9
        );
        Ok(floor)
    }

    /// The floor in ms of a frame that moves `bytes` and evaluates `evals` densities.
    pub fn ms(&self, bytes: f64, evals: f64) -> f64 {
        let memory = bytes / self.bytes_per_s;
        let math = evals * FLOPS_PER_EVAL / self.flops_per_s;
        memory.max(math) * 1e3
    }
}
