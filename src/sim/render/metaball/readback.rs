//! What tests and debugging read back of the frame last rendered: the S-buffer's
//! per-pixel lists, the per-tile lists, the metaballs' view depths, per-pixel hits.
use super::buffers::MetaballBuffers;
use super::renderer::FluidRenderer;
use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::render::ListKind;

impl FluidRenderer {
    /// The S-buffer's per-pixel lists of the frame last rendered (tests and debugging).
    pub fn sbuffer_lists(&self, ctx: &Context, b: &MetaballBuffers) -> Result<Vec<Vec<u32>>> {
        if self.settings.list != ListKind::Sbuffer {
            return Err(Error::Param("not an S-buffer renderer".into()));
        }
        let px = self.settings.pixels() as usize;
        let ends: Vec<u32> = ctx.readback(&b.offsets, 0, px)?;
        let total = ends.last().copied().unwrap_or(0) as usize;
        let list: Vec<u32> = ctx.readback(&b.list, 0, total.min(b.list_capacity as usize))?;
        Ok((0..px)
            .map(|p| {
                let start = if p == 0 { 0 } else { ends[p - 1] as usize };
                list[start..ends[p] as usize].to_vec()
            })
            .collect())
    }

    /// Per-pixel (t, normal) of the primary hits (t < 0: none), when built with debug.
    pub fn debug(&self, ctx: &Context, b: &MetaballBuffers) -> Result<Vec<[f32; 4]>> {
        if !b.debug_on {
            return Err(Error::Param(
                "the renderer's buffers were made without debug output".into(),
            ));
        }
        ctx.readback(&b.debug, 0, self.settings.pixels() as usize)
    }

    /// Each tile's metaballs in list order (tiles and compute-built S-buffers).
    pub fn tile_lists(&self, ctx: &Context, b: &MetaballBuffers) -> Result<Vec<Vec<u32>>> {
        if !self.settings.bins_tiles() {
            return Err(Error::Param("the frame binned no tiles".into()));
        }
        let t = &b.tiles;
        let ranges: Vec<[u32; 2]> = ctx.readback(&t.tile_ranges, 0, t.tiles as usize)?;
        let end = ranges.iter().map(|r| r[1]).max().unwrap_or(0) as usize;
        let ids: Vec<u32> = ctx.readback(&t.pair_ids, 0, end)?;
        Ok(ranges
            .iter()
            .map(|r| ids[r[0] as usize..r[1] as usize].to_vec())
            .collect())
    }

    /// Every metaball's view depth as the GPU computed it (sorted lists, tiles), for `n`.
    pub fn metaball_depths(
        &self,
        ctx: &Context,
        b: &MetaballBuffers,
        n: usize,
    ) -> Result<Vec<f32>> {
        if !(self.settings.sorts_lists() || self.settings.bins_tiles()) {
            return Err(Error::Param("the frame computed no metaball depths".into()));
        }
        ctx.readback(&b.depths, 0, n)
    }
}
