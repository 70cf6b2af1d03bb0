//! Prefix sum of u32, work-efficient and multi-level, for any N:
//! - level pass 1: each invocation sums a chunk of CHUNK contiguous elements (128-bit
//!   loads, no barriers); the chunk sums are the next level, scanned recursively;
//! - level pass 2: each invocation scans its chunk serially from its offset;
//! - the top level (at most WG * IPT elements) is one workgroup: a workgroup scan with
//!   subgroup arithmetic where the device has it, shared memory where it has not. Where a
//!   level has at most TOP_MOST chunks, the last workgroup of its pass 1 scans their sums
//!   (TOP): such a scan is two dispatches.
//!
//! About 3N memory traffic. Arrays longer than one storage-buffer binding
//! (maxStorageBufferRange) are processed in bound segments.
use crate::error::{Error, Result};
use crate::pass::{Defines, PassKey};
use crate::{BindingDecl, Buffer, ComputePipeline, Context, Guard, Interface};
use ash::vk;
use bytemuck::{Pod, Zeroable};

pub const WG: u32 = 256;
/// Elements per invocation of a level pass.
pub const CHUNK: u32 = 64;
/// Elements per invocation of the top-level workgroup scan.
pub const IPT: u32 = 16;
/// Most elements the top level scans in one workgroup.
pub const BLOCK: u64 = (WG * IPT) as u64;
/// Most chunk sums the last workgroup of a level's first pass scans itself (64 per
/// invocation): a scan of up to CHUNK * TOP_MOST elements (4M) is two dispatches. (A
/// 512 x 512 S-buffer's counts and their total, 2^18 + 1, are 4097 chunks: one past BLOCK.)
pub const TOP_MOST: u64 = WG as u64 * 64;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanKind {
    Exclusive,
    Inclusive,
}

/// Which workgroup scan the top level uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScanVariant {
    /// Subgroup arithmetic where the device has it, else shared memory.
    Auto,
    Subgroup,
    SharedMemory,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ScanPush {
    pub n: u32,
    /// Index of this segment's first chunk in the chunk sums.
    pub base: u32,
    pub flags: u32,
}
const _: () = assert!(std::mem::size_of::<ScanPush>() == 12);
const INCLUSIVE: u32 = 1;

/// The scan passes' interface (glsl/primitives/scan_io.glsl). Written out rather than
/// declared with `gpu_interface!` because a level binds sub-ranges of raw buffers.
pub struct ScanIo;

/// The five views of one scan dispatch: input and output twice (uvec4 and uint), sums.
pub struct ScanBufs {
    pub in4: vk::DescriptorBufferInfo,
    pub in1: vk::DescriptorBufferInfo,
    pub out4: vk::DescriptorBufferInfo,
    pub out1: vk::DescriptorBufferInfo,
    pub sums: vk::DescriptorBufferInfo,
}

impl Interface for ScanIo {
    const NAME: &'static str = "ScanIo";
    const PREFIX: &'static str = "SCAN";
    const BINDINGS: &'static [BindingDecl] = &[
        BindingDecl {
            name: "in4",
            binding: 0,
        },
        BindingDecl {
            name: "in1",
            binding: 1,
        },
        BindingDecl {
            name: "out4",
            binding: 2,
        },
        BindingDecl {
            name: "out1",
            binding: 3,
        },
        BindingDecl {
            name: "sums",
            binding: 4,
        },
    ];
    type Push = ScanPush;
    type Bufs<'a> = ScanBufs;
    fn buffers(b: &ScanBufs) -> Vec<(u32, vk::DescriptorBufferInfo)> {
        vec![
            (0, b.in4),
            (1, b.in1),
            (2, b.out4),
            (3, b.out1),
            (4, b.sums),
        ]
    }
}

/// Pipelines (size-independent).
pub struct ScanPass {
    chunk_reduce: ComputePipeline<ScanIo>,
    /// The level pass 1 whose last workgroup also scans the chunk sums (at most TOP_MOST).
    chunk_reduce_top: ComputePipeline<ScanIo>,
    chunk_down: ComputePipeline<ScanIo>,
    top: ComputePipeline<ScanIo>,
    pub uses_subgroups: bool,
}

/// Per-level chunk-sum buffers for arrays of up to `capacity` elements.
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

fn range(b: vk::Buffer, start: u64, len: u64) -> vk::DescriptorBufferInfo {
    vk::DescriptorBufferInfo {
        buffer: b,
        offset: start * 4,
        range: len * 4,
    }
}

/// Whether a scan adds with subgroup arithmetic (else in shared memory).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Subgroups(pub bool);

impl PassKey for Subgroups {
    fn all() -> Vec<Self> {
        vec![Self(false), Self(true)]
    }
    fn defines(&self) -> Defines {
        ScanPass::defines(self.0)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }
}

crate::compute_pass!(
    /// A level's chunk sums.
    pub SCAN_CHUNK_SUMS: ScanIo, Subgroups = "scan chunk sums", "primitives/scan_chunk_reduce.comp", "TOP" = "0"
);
crate::compute_pass!(
    /// A level's chunk sums, its last workgroup scanning them (up to TOP_MOST chunks).
    pub SCAN_CHUNK_SUMS_TOP: ScanIo, Subgroups = "scan chunk sums and top", "primitives/scan_chunk_reduce.comp", "TOP" = "1"
);
crate::compute_pass!(pub SCAN_CHUNKS: ScanIo, Subgroups = "scan chunks", "primitives/scan_chunk_down.comp");
crate::compute_pass!(pub SCAN_TOP: ScanIo, Subgroups = "scan top", "primitives/scan_block.comp");

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
        let key = Subgroups(subgroup);
        let chunk_reduce = Guard::new(ctx, SCAN_CHUNK_SUMS.pipeline(ctx, &key, WG, &[])?);
        let chunk_reduce_top = Guard::new(ctx, SCAN_CHUNK_SUMS_TOP.pipeline(ctx, &key, WG, &[])?);
        let chunk_down = Guard::new(ctx, SCAN_CHUNKS.pipeline(ctx, &key, WG, &[])?);
        let top = SCAN_TOP.pipeline(ctx, &key, WG, &[])?;
        Ok(Self {
            chunk_reduce: chunk_reduce.take(),
            chunk_reduce_top: chunk_reduce_top.take(),
            chunk_down: chunk_down.take(),
            top,
            uses_subgroups: subgroup,
        })
    }

    /// The scan shaders' defines (also the shader registry's variants).
    pub fn defines(subgroup: bool) -> [(&'static str, String); 3] {
        [
            ("SUBGROUP", (subgroup as u32).to_string()),
            ("IPT", format!("{IPT}u")),
            ("CHUNK", format!("{CHUNK}u")),
        ]
    }

    pub fn scratch(&self, ctx: &Context, capacity: u64) -> Result<ScanScratch> {
        let mut levels = Guard::new(ctx, Vec::new());
        let mut n = capacity;
        while n > BLOCK {
            n = n.div_ceil(CHUNK as u64);
            let name = format!("scan chunk sums {}", levels.len());
            // One element past the sums: the fused top's arrival counter, kept at 0.
            levels.push(ctx.storage_buffer(&name, n * 4 + 4)?);
        }
        if !levels.is_empty() {
            ctx.one_shot(|cmd| levels.iter().for_each(|b| ctx.fill(cmd, b, 0)))?;
        }
        Ok(ScanScratch {
            levels: levels.take(),
            capacity,
        })
    }

    /// Record a scan of `n` u32 from `input` into `output` (may be the same buffer).
    #[allow(clippy::too_many_arguments)]
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
        if n <= BLOCK {
            let push = ScanPush {
                n: n as u32,
                base: 0,
                flags: inclusive,
            };
            let (i, o) = (range(input, 0, n), range(output, 0, n));
            let bufs = ScanBufs {
                in4: i,
                in1: i,
                out4: o,
                out1: o,
                sums: i,
            };
            self.top.dispatch_groups(ctx, cmd, &bufs, &push, 1);
            return;
        }
        let chunk = CHUNK as u64;
        let sums = vk::DescriptorBufferInfo {
            buffer: scratch.levels[level].raw,
            offset: 0,
            range: vk::WHOLE_SIZE,
        };
        // Segments: the most whole blocks one binding may cover.
        let seg = (ctx.max_storage_range() / 4 / BLOCK).max(1) * BLOCK;
        let dispatch = |p: &ComputePipeline<ScanIo>, flags: u32| {
            for s in 0..n.div_ceil(seg) {
                let (start, len) = (s * seg, seg.min(n - s * seg));
                let push = ScanPush {
                    n: len as u32,
                    base: (start / chunk) as u32,
                    flags,
                };
                let (i, o) = (range(input, start, len), range(output, start, len));
                let groups = len.div_ceil(chunk).div_ceil(WG as u64);
                let bufs = ScanBufs {
                    in4: i,
                    in1: i,
                    out4: o,
                    out1: o,
                    sums,
                };
                p.dispatch_groups(ctx, cmd, &bufs, &push, groups);
            }
        };
        let next = scratch.levels[level].raw;
        let chunks = n.div_ceil(chunk);
        if chunks <= TOP_MOST && n <= seg {
            // One segment whose chunk sums one workgroup scans: that workgroup is the
            // last of the sums pass to finish.
            dispatch(&self.chunk_reduce_top, 0);
            dispatch(&self.chunk_down, inclusive);
            return;
        }
        dispatch(&self.chunk_reduce, 0);
        self.level(
            ctx,
            cmd,
            next,
            next,
            chunks,
            ScanKind::Exclusive,
            scratch,
            level + 1,
        );
        dispatch(&self.chunk_down, inclusive);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.chunk_reduce.destroy(ctx);
        self.chunk_reduce_top.destroy(ctx);
        self.chunk_down.destroy(ctx);
        self.top.destroy(ctx);
    }
}
