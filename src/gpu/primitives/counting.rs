//! Atomic-grid counting sort (seed 002): count per cell with atomicAdd (each element keeps
//! its in-cell rank), exclusive prefix sum of the counts gives cell starts, scatter to
//! start + rank, then each cell's values in ascending order (cell_order.comp): the
//! atomics' ranks follow the scheduling, and a permutation that changed from run to run
//! changed every sum over a cell's elements. O(N + cells + sum of squared cell counts).
use super::scan::{ScanKind, ScanPass, ScanScratch};
use crate::error::{Error, Result};
use crate::{Buffer, ComputeDesc, ComputePipeline, Context, Guard};
use ash::vk;
use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CountPush {
    pub n: u32,
    pub cells: u32,
}

crate::gpu_interface! {
    /// glsl/primitives/count.comp
    pub CountIo / CountBufs: "COUNT", push CountPush { keys = 0, counts = 1, rank = 2 }
}

crate::gpu_interface! {
    /// glsl/primitives/scatter.comp
    pub ScatterIo / ScatterBufs: "SCATTER", push CountPush {
        keys = 0, rank = 1, starts = 2, vals = 3, sorted_keys = 4, sorted_vals = 5,
    }
}

crate::gpu_interface! {
    /// glsl/primitives/cell_order.comp
    pub OrderIo / OrderBufs: "ORDER", push CountPush { counts = 0, starts = 1, sorted_vals = 2 }
}

crate::gpu_interface! {
    /// glsl/primitives/gather.comp; push: n.
    pub GatherIo / GatherBufs: "GATHER", push u32 { perm = 0, src = 1, dst = 2 }
}

pub struct CountingSort {
    count: ComputePipeline<CountIo>,
    scatter: ComputePipeline<ScatterIo>,
    order: ComputePipeline<OrderIo>,
}

/// Buffers for up to `capacity` elements and `cells` cells.
pub struct CountingBuffers {
    /// Per-cell counts; `counts[cells]` counts out-of-range keys.
    pub counts: Buffer,
    /// Exclusive scan of counts: the first sorted slot of each cell.
    pub starts: Buffer,
    pub rank: Buffer,
    pub scan: ScanScratch,
    pub cells: u32,
    pub capacity: u64,
}

impl CountingBuffers {
    pub fn new(ctx: &Context, scan: &ScanPass, capacity: u64, cells: u32) -> Result<Self> {
        if cells == 0 {
            return Err(Error::Param("counting sort needs at least one cell".into()));
        }
        let buf = |name: &str, bytes| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let counts = buf("cell counts", (cells as u64 + 1) * 4)?;
        let starts = buf("cell starts", cells as u64 * 4)?;
        let rank = buf("in-cell rank", capacity * 4)?;
        let scan = scan.scratch(ctx, cells as u64)?;
        Ok(Self {
            counts: counts.take(),
            starts: starts.take(),
            rank: rank.take(),
            scan,
            cells,
            capacity,
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_buffer(&mut self.counts);
        ctx.destroy_buffer(&mut self.starts);
        ctx.destroy_buffer(&mut self.rank);
        self.scan.destroy(ctx);
    }
}

impl CountingSort {
    pub fn new(ctx: &Context) -> Result<Self> {
        let desc = |name, shader| ComputeDesc::plain(name, shader, &[], 256);
        let count = Guard::new(
            ctx,
            ComputePipeline::new(ctx, &desc("count", "primitives/count.comp"))?,
        );
        let scatter = Guard::new(
            ctx,
            ComputePipeline::new(ctx, &desc("scatter", "primitives/scatter.comp"))?,
        );
        let order = ComputePipeline::new(ctx, &desc("cell order", "primitives/cell_order.comp"))?;
        Ok(Self {
            count: count.take(),
            scatter: scatter.take(),
            order,
        })
    }

    /// Record the sort of `n` keys (< cells) with their values into sorted_keys/sorted_vals.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scan: &ScanPass,
        b: &CountingBuffers,
        keys: &Buffer,
        vals: &Buffer,
        sorted_keys: &Buffer,
        sorted_vals: &Buffer,
        n: u64,
    ) -> Result<()> {
        if n > b.capacity {
            return Err(Error::Param(format!(
                "counting sort of {n} elements exceeds capacity {}",
                b.capacity
            )));
        }
        let push = CountPush {
            n: n as u32,
            cells: b.cells,
        };
        ctx.fill(cmd, &b.counts, 0);
        let bufs = CountBufs {
            keys,
            counts: &b.counts,
            rank: &b.rank,
        };
        self.count.dispatch(ctx, cmd, &bufs, &push, n);
        scan.record(
            ctx,
            cmd,
            &b.counts,
            &b.starts,
            b.cells as u64,
            ScanKind::Exclusive,
            &b.scan,
        )?;
        let bufs = ScatterBufs {
            keys,
            rank: &b.rank,
            starts: &b.starts,
            vals,
            sorted_keys,
            sorted_vals,
        };
        self.scatter.dispatch(ctx, cmd, &bufs, &push, n);
        let bufs = OrderBufs {
            counts: &b.counts,
            starts: &b.starts,
            sorted_vals,
        };
        self.order.dispatch(ctx, cmd, &bufs, &push, b.cells as u64);
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.count.destroy(ctx);
        self.scatter.destroy(ctx);
        self.order.destroy(ctx);
    }
}

/// `dst[i] = src[perm[i]]` for vec4 attributes.
pub struct GatherPass {
    pipeline: ComputePipeline<GatherIo>,
}

impl GatherPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: ComputePipeline::new(
                ctx,
                &ComputeDesc::plain("gather", "primitives/gather.comp", &[], 256),
            )?,
        })
    }

    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        perm: &Buffer,
        src: &Buffer,
        dst: &Buffer,
        n: u32,
    ) {
        self.pipeline
            .dispatch(ctx, cmd, &GatherBufs { perm, src, dst }, &n, n as u64);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
