//! Sorting networks on key/value u32 pairs, in place, for any n: Batcher's odd-even merge
//! sort (seeds 000 and 003) and bitonic sort (Le Grand's baseline). Tiles of BLOCK
//! elements are sorted (and, for bitonic, merged) in shared memory; the remaining
//! comparator stages are one dispatch each.
use crate::error::{Error, Result};
use crate::{Buffer, ComputePipeline, Context};
use ash::vk;
use bytemuck::{Pod, Zeroable};

pub const BLOCK: u32 = 2048;
const WG: u32 = 256;

crate::compute_pass!(pub ODD_EVEN: SortIo, () = "odd-even merge sort", "primitives/oddeven.comp");
crate::compute_pass!(pub BITONIC: SortIo, () = "bitonic sort", "primitives/bitonic.comp");

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Network {
    OddEven,
    Bitonic,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SortPush {
    pub n: u32,
    pub p: u32,
    pub k: u32,
    pub mode: u32,
}
const _: () = assert!(std::mem::size_of::<SortPush>() == 16);
const LOCAL_SORT: u32 = 0;
const GLOBAL: u32 = 1;
const LOCAL_MERGE: u32 = 2;

crate::gpu_interface! {
    /// glsl/primitives/sort_common.glsl (oddeven.comp, bitonic.comp)
    pub SortIo / SortBufs: "SORT", push SortPush { keys = 0, vals = 1 }
}

pub struct NetworkSort {
    pipeline: ComputePipeline<SortIo>,
    pub network: Network,
}

impl NetworkSort {
    pub fn new(ctx: &Context, network: Network) -> Result<Self> {
        let decl = match network {
            Network::OddEven => ODD_EVEN,
            Network::Bitonic => BITONIC,
        };
        Ok(Self {
            pipeline: decl.pipeline(ctx, &(), WG, &[BLOCK])?,
            network,
        })
    }

    /// Record sorting the first `n` pairs of `keys`/`vals` by key (not stable).
    /// Returns the number of dispatches recorded.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        keys: &Buffer,
        vals: &Buffer,
        n: u64,
    ) -> Result<u32> {
        if n > (1u64 << 31) {
            return Err(Error::Param(format!("sort of {n} elements: at most 2^31")));
        }
        if keys.size < n * 4 || vals.size < n * 4 {
            return Err(Error::Param(format!(
                "sort of {n} elements: '{}' or '{}' is too small",
                keys.name, vals.name
            )));
        }
        if n <= 1 {
            return Ok(0);
        }
        let n32 = n as u32;
        let bufs = SortBufs { keys, vals };
        let tiles = n.div_ceil(BLOCK as u64);
        let pow2 = n.next_power_of_two();
        let mut dispatches = 0;
        let mut run = |push: SortPush, groups: u64| {
            self.pipeline
                .dispatch_groups(ctx, cmd, &bufs, &push, groups);
            dispatches += 1;
        };
        let local = |mode| SortPush {
            n: n32,
            p: 0,
            k: 0,
            mode,
        };
        let global = |p: u64, k: u64| SortPush {
            n: n32,
            p: p as u32,
            k: k as u32,
            mode: GLOBAL,
        };
        run(local(LOCAL_SORT), tiles);
        let block = BLOCK as u64;
        let wg = WG as u64;
        match self.network {
            Network::OddEven => {
                let mut p = block;
                while p < pow2 {
                    let mut k = p;
                    while k >= 1 {
                        run(global(p, k), n.div_ceil(wg));
                        k >>= 1;
                    }
                    p <<= 1;
                }
            }
            Network::Bitonic => {
                let half = (pow2 / 2).div_ceil(wg);
                let mut s = 2 * block;
                while s <= pow2 {
                    run(global(s, 0), half);
                    let mut d = s / 4;
                    while d >= block {
                        run(global(s, d), half);
                        d >>= 1;
                    }
                    run(local(LOCAL_MERGE), tiles);
                    s <<= 1;
                }
            }
        }
        Ok(dispatches)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
