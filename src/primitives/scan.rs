//! Prefix sum of u32, reduce-then-scan: (1) each block of WG*ITEMS elements is summed,
//! (2) the block sums are scanned recursively, (3) each block is scanned in shared memory
//! with its offset added. 3N memory traffic, O(N) work, any N: arrays longer than one
//! storage-buffer binding (maxStorageBufferRange) are processed in bound segments.
use crate::error::{Error, Result};
use crate::gpu::{Buffer, ComputeDesc, ComputePipeline, Context};
use ash::vk;
use bytemuck::{Pod, Zeroable};

pub const WG: u32 = 256;
pub const ITEMS: u32 = 8;
/// Elements per block.
pub const BLOCK: u64 = (WG * ITEMS) as u64;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanKind {
    Exclusive,
    Inclusive,
}

/// Which workgroup scan the shaders use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanVariant {
    /// Subgroup arithmetic where the device has it, else shared memory.
    Auto,
    Subgroup,
    SharedMemory,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ScanPush {
    n: u32,
    block_base: u32,
    flags: u32,
}
const _: () = assert!(std::mem::size_of::<ScanPush>() == 12);
const INCLUSIVE: u32 = 1;
const HAS_OFFSETS: u32 = 2;

/// Pipelines (size-independent).
pub struct ScanPass {
    reduce: ComputePipeline,
    block: ComputePipeline,
    pub uses_subgroups: bool,
}

/// Per-level block-sum buffers for arrays of up to `capacity` elements.
pub struct ScanScratch {
    levels: Vec<Buffer>,
    pub capacity: u64,
}

impl ScanScratch {
    pub fn destroy(&mut self, ctx: &Context) {
        for b in &mut self.levels {
            ctx.destroy_buffer(b);
        }
    }

    pub fn bytes(&self) -> u64 {
        self.levels.iter().map(|b| b.size).sum()
    }
}

impl ScanPass {
    pub fn new(ctx: &Context, variant: ScanVariant) -> Result<Self> {
        let subgroup = match variant {
            ScanVariant::Auto => ctx.info.subgroup_arithmetic,
            ScanVariant::SharedMemory => false,
            ScanVariant::Subgroup => {
                if !ctx.info.subgroup_arithmetic {
                    return Err(Error::Unsupported(format!(
                        "{} has no subgroup arithmetic in compute shaders",
                        ctx.info.name
                    )));
                }
                true
            }
        };
        let defines = [("SUBGROUP", (subgroup as u32).to_string())];
        let desc = |name, shader, buffers| ComputeDesc {
            name,
            shader,
            defines: &defines,
            local_size: WG,
            spec: &[ITEMS],
            buffers,
            push_size: std::mem::size_of::<ScanPush>() as u32,
        };
        Ok(Self {
            reduce: ComputePipeline::new(
                ctx,
                &desc("scan reduce", "primitives/scan_reduce.comp", 2),
            )?,
            block: ComputePipeline::new(ctx, &desc("scan block", "primitives/scan_block.comp", 3))?,
            uses_subgroups: subgroup,
        })
    }

    pub fn scratch(&self, ctx: &Context, capacity: u64) -> Result<ScanScratch> {
        let mut levels = Vec::new();
        let mut n = capacity;
        while n > BLOCK {
            n = n.div_ceil(BLOCK);
            levels.push(ctx.storage_buffer(&format!("scan block sums {}", levels.len()), n * 4)?);
        }
        Ok(ScanScratch { levels, capacity })
    }

    /// Record a scan of `n` u32 from `input` into `output` (may be the same buffer).
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        input: &Buffer,
        output: &Buffer,
        n: u64,
        kind: ScanKind,
        scratch: &ScanScratch,
    ) -> Result<()> {
        if n > scratch.capacity {
            return Err(Error::Param(format!(
                "scan of {n} elements exceeds its scratch capacity {}",
                scratch.capacity
            )));
        }
        if n > u32::MAX as u64 {
            return Err(Error::Param(format!(
                "scan of {n} elements: at most 2^32 - 1"
            )));
        }
        if input.size < n * 4 || output.size < n * 4 {
            return Err(Error::Param(format!(
                "scan of {n} elements: buffers '{}' / '{}' are too small",
                input.name, output.name
            )));
        }
        self.level(ctx, cmd, input.raw, output.raw, n, kind, scratch, 0);
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn level(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        input: vk::Buffer,
        output: vk::Buffer,
        n: u64,
        kind: ScanKind,
        scratch: &ScanScratch,
        level: usize,
    ) {
        if n == 0 {
            return;
        }
        let inclusive = if kind == ScanKind::Inclusive {
            INCLUSIVE
        } else {
            0
        };
        // Segment length: the most whole blocks one binding may cover.
        let seg = (ctx.max_storage_range() / 4 / BLOCK).max(1) * BLOCK;
        let range = |b: vk::Buffer, start: u64, len: u64| vk::DescriptorBufferInfo {
            buffer: b,
            offset: start * 4,
            range: len * 4,
        };
        let whole = |b: vk::Buffer| vk::DescriptorBufferInfo {
            buffer: b,
            offset: 0,
            range: vk::WHOLE_SIZE,
        };
        let segments = (0..n.div_ceil(seg)).map(|s| (s * seg, seg.min(n - s * seg)));
        if n <= BLOCK {
            let push = ScanPush {
                n: n as u32,
                block_base: 0,
                flags: inclusive,
            };
            let infos = [range(input, 0, n), range(output, 0, n), range(input, 0, n)];
            self.block.dispatch_groups(ctx, cmd, &infos, &push, 1);
            return;
        }
        let sums = scratch.levels[level].raw;
        for (start, len) in segments.clone() {
            let push = ScanPush {
                n: len as u32,
                block_base: (start / BLOCK) as u32,
                flags: 0,
            };
            let infos = [range(input, start, len), whole(sums)];
            self.reduce
                .dispatch_groups(ctx, cmd, &infos, &push, len.div_ceil(BLOCK));
        }
        ctx.compute_barrier(cmd);
        self.level(
            ctx,
            cmd,
            sums,
            sums,
            n.div_ceil(BLOCK),
            ScanKind::Exclusive,
            scratch,
            level + 1,
        );
        ctx.compute_barrier(cmd);
        for (start, len) in segments {
            let push = ScanPush {
                n: len as u32,
                block_base: (start / BLOCK) as u32,
                flags: inclusive | HAS_OFFSETS,
            };
            let infos = [
                range(input, start, len),
                range(output, start, len),
                whole(sums),
            ];
            self.block
                .dispatch_groups(ctx, cmd, &infos, &push, len.div_ceil(BLOCK));
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.reduce.destroy(ctx);
        self.block.destroy(ctx);
    }
}
