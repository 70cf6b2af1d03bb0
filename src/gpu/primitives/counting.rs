//! Atomic-grid counting sort (seed 002): count per cell with atomicAdd (each element keeps
//! its in-cell rank), exclusive prefix sum of the counts gives cell starts, scatter to
//! start + rank, then each cell's values in ascending order (cell_order.comp): the
//! atomics' ranks follow the scheduling, and a permutation that changed from run to run
//! changed every sum over a cell's elements. O(N + cells + sum of squared cell counts).
use super::scan::{ScanKind, ScanPass, ScanScratch};
use crate::error::{Error, Result};
use crate::{Buffer, ComputePipeline, Context, Guard};
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

/// Attributes one gather dispatch moves.
pub const GATHER_SLOTS: usize = 4;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GatherPush {
    pub n: u32,
    /// Slots in use (1..=GATHER_SLOTS).
    pub count: u32,
}

crate::gpu_interface! {
    /// glsl/primitives/gather.comp
    pub GatherIo / GatherBufs: "GATHER", push GatherPush {
        perm = 0, src0 = 1, src1 = 2, src2 = 3, src3 = 4, dst0 = 5, dst1 = 6, dst2 = 7, dst3 = 8,
    }
}

impl CountPush {
    /// The push constants of a sort of `n` elements, which `b` must hold.
    fn checked(b: &CountingBuffers, n: u64) -> Result<Self> {
        if n > b.capacity {
            return Err(Error::Param(format!(
                "counting sort of {n} elements exceeds capacity {}",
                b.capacity
            )));
        }
        Ok(Self {
            n: n as u32,
            cells: b.cells,
        })
    }
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

crate::compute_pass!(pub COUNT: CountIo, () = "count", "primitives/count.comp");
crate::compute_pass!(pub SCATTER: ScatterIo, () = "scatter", "primitives/scatter.comp");
crate::compute_pass!(pub CELL_ORDER: OrderIo, () = "cell order", "primitives/cell_order.comp");
crate::compute_pass!(pub GATHER: GatherIo, () = "gather", "primitives/gather.comp");

impl CountingSort {
    pub fn new(ctx: &Context) -> Result<Self> {
        let count = Guard::new(ctx, COUNT.pipeline(ctx, &(), 256, &[])?);
        let scatter = Guard::new(ctx, SCATTER.pipeline(ctx, &(), 256, &[])?);
        let order = CELL_ORDER.pipeline(ctx, &(), 256, &[])?;
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
        let push = CountPush::checked(b, n)?;
        ctx.fill(cmd, &b.counts, 0);
        let bufs = CountBufs {
            keys,
            counts: &b.counts,
            rank: &b.rank,
        };
        self.count.dispatch(ctx, cmd, &bufs, &push, n);
        self.record_counted(ctx, cmd, scan, b, keys, vals, sorted_keys, sorted_vals, n)
    }

    /// The sort after its first pass, where another pass has counted the keys into
    /// `b.counts` and `b.rank` as count.comp does (nb_keys.comp with NB_CELL_COUNTS).
    #[allow(clippy::too_many_arguments)]
    pub fn record_counted(
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
        let push = CountPush::checked(b, n)?;
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

/// `dst[i] = src[perm[i]]` for vec4 attributes, up to [`GATHER_SLOTS`] per dispatch.
pub struct GatherPass {
    pipeline: ComputePipeline<GatherIo>,
}

impl GatherPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: GATHER.pipeline(ctx, &(), 256, &[])?,
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
        self.record_many(ctx, cmd, perm, &[(src, dst)], n);
    }

    /// Every (src, dst) pair reordered by `perm`, [`GATHER_SLOTS`] to a dispatch.
    pub fn record_many(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        perm: &Buffer,
        pairs: &[(&Buffer, &Buffer)],
        n: u32,
    ) {
        for chunk in pairs.chunks(GATHER_SLOTS) {
            // Slots past the chunk repeat its first pair (bound, never written).
            let at = |k: usize| chunk.get(k).unwrap_or(&chunk[0]);
            let bufs = GatherBufs {
                perm,
                src0: at(0).0,
                src1: at(1).0,
                src2: at(2).0,
                src3: at(3).0,
                dst0: at(0).1,
                dst1: at(1).1,
                dst2: at(2).1,
                dst3: at(3).1,
            };
            let push = GatherPush {
                n,
                count: chunk.len() as u32,
            };
            self.pipeline.dispatch(ctx, cmd, &bufs, &push, n as u64);
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
