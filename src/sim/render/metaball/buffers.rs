//! The metaball renderer's sized buffers: lists for width x height, up to `n_capacity`
//! metaballs, per-slot readbacks. Apart from the pipelines (renderer.rs), so a sweep over
//! sizes rebuilds buffers only.
use super::settings::{MetaballSettings, RenderParams};
use super::stats::GpuStats;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, Guard, MemoryLocation};
use crate::primitives::bounds::BoundsBuffers;
use crate::primitives::scan::{ScanPass, ScanScratch};
use crate::render::ListKind;

/// Sized buffers: lists for width x height, up to `n_capacity` metaballs, per-slot readbacks.
pub struct MetaballBuffers {
    pub(super) params: Buffer,
    pub(super) offsets: Buffer,
    pub(super) list: Buffer,
    pub(super) heads: Buffer,
    pub(super) nodes: Buffer,
    pub(super) stats: Buffer,
    pub pixels: Buffer,
    pub(super) debug: Buffer,
    pub(super) sky: Buffer,
    /// Sorted S-buffer: every metaball's view depth.
    pub(super) depths: Buffer,
    /// The opaque layer the caller draws (settings.opaque): W*H RGBA8, then W*H f32 depths.
    pub opaque: Buffer,
    /// The occupancy grid (glsl/render/metaball/occupancy.glsl): a header and a word per
    /// cell, where the march has secondary rays (a retune may turn `occupancy` on).
    pub(super) occupancy: Buffer,
    /// With the opaque layer: per pixel, the NDC depth of the first surface the primary
    /// ray meets (fluid or opaque layer; 1 = none), for layers drawn over the picture.
    pub scene_depth: Buffer,
    pub(super) sky_size: (u32, u32),
    pub(super) bounds: BoundsBuffers,
    pub(super) scan: ScanScratch,
    pub(super) stats_readback: Vec<Buffer>,
    pub(super) pixels_readback: Vec<Buffer>,
    /// Entries of the S-buffer list or the A-buffer node pool.
    pub list_capacity: u64,
    pub debug_on: bool,
    /// The other surfaces' buffers (none for the metaballs).
    pub surface: Option<crate::render::surface::SurfaceBuffers>,
    /// The per-tile lists (token sizes unless the frame bins tiles).
    pub tiles: super::tiles::TileBuffers,
}

/// Bytes of the occupancy grid: its header's 16 words and 64^3 cells (occupancy.glsl's
/// OCC_CELLS and OCC_DIM).
pub const OCCUPANCY_BYTES: u64 = (16 + 64 * 64 * 64) * 4;

/// Bytes of one list entry: an S-buffer metaball index, an A-buffer (index, next) node.
pub fn entry_bytes(list: ListKind) -> u64 {
    match list {
        ListKind::Abuffer => 8,
        // A pair's key, metaball and gathered (xyz, depth).
        ListKind::Tiles => super::tiles::PAIR_BYTES,
        _ => 4,
    }
}

/// Bytes per pixel of a frame of `s` with `slots` in flight, an upper bound on what
/// `with_capacity` makes: all its pixel-sized buffers together, the list at its first
/// capacity of 4 entries a pixel (`with_capacity` caps it at one binding's range) and the
/// opaque layer's colour target included; and the largest one alone, which one storage
/// binding must address.
pub fn pixel_bytes(s: &MetaballSettings, slots: usize) -> (u64, u64) {
    let (sbuf, abuf) = (s.list == ListKind::Sbuffer, s.list == ListKind::Abuffer);
    let list = 4 * entry_bytes(s.list);
    // The picture and its readbacks.
    let mut total = 4 + 4 * slots as u64;
    let mut largest = 4;
    if sbuf {
        total += 4 + list; // offsets, list (the scan's scratch is 1/16 of a byte)
    }
    if abuf {
        total += 4 + list; // heads, nodes
    }
    if s.opaque {
        total += 8 + 4 + 4 + 4; // opaque layer, scene depth, the target's colour and depth
        largest = 8;
    }
    let (surface, widest) = crate::render::surface::buffers::pixel_bytes(s.surface);
    total += surface;
    largest = largest.max(widest);
    (total, largest)
}

fn load_sky(path: &str) -> Result<(u32, u32, Vec<u32>)> {
    let img = image::open(path).map_err(|e| Error::Image {
        path: path.into(),
        message: e.to_string(),
    })?;
    let rgba = img.to_rgba8();
    let (w, h) = rgba.dimensions();
    let px = rgba.pixels().map(|p| u32::from_le_bytes(p.0)).collect();
    Ok((w, h, px))
}

impl MetaballBuffers {
    /// Bytes of every buffer the renderer holds for its frames (lists, picture, sky,
    /// layers, readbacks, the per-tile lists and another surface's): its memory by
    /// ownership, not by buffer names.
    pub fn bytes(&self) -> u64 {
        let own = [
            &self.params,
            &self.offsets,
            &self.list,
            &self.heads,
            &self.nodes,
            &self.stats,
            &self.pixels,
            &self.debug,
            &self.sky,
            &self.depths,
            &self.opaque,
            &self.scene_depth,
            &self.occupancy,
        ];
        let readbacks = self.stats_readback.iter().chain(&self.pixels_readback);
        let buffers: u64 = own.into_iter().chain(readbacks).map(|b| b.size).sum();
        let surface = self.surface.as_ref().map_or(0, |s| s.bytes());
        buffers + self.bounds.bytes() + self.scan.bytes() + self.tiles.held_bytes() + surface
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.params,
            &mut self.offsets,
            &mut self.list,
            &mut self.heads,
            &mut self.nodes,
            &mut self.stats,
            &mut self.pixels,
            &mut self.debug,
            &mut self.sky,
            &mut self.depths,
            &mut self.opaque,
            &mut self.scene_depth,
            &mut self.occupancy,
        ] {
            ctx.destroy_buffer(b);
        }
        for b in self
            .stats_readback
            .iter_mut()
            .chain(self.pixels_readback.iter_mut())
        {
            ctx.destroy_buffer(b);
        }
        self.bounds.destroy(ctx);
        self.scan.destroy(ctx);
        if let Some(sb) = &mut self.surface {
            sb.destroy(ctx);
        }
        self.tiles.destroy(ctx);
    }

    /// RGBA8 pixels of the frame last rendered in `slot` (after its fence).
    pub fn pixels(&self, slot: usize) -> &[u8] {
        self.pixels_readback[slot].mapped().expect("mapped")
    }

    /// Buffers for `s` and up to `n_capacity` metaballs, the list starting at `capacity`
    /// entries (it grows on overflow).
    #[allow(clippy::too_many_arguments)]
    pub fn with_capacity(
        ctx: &Context,
        s: &MetaballSettings,
        scan: &ScanPass,
        n_capacity: u64,
        slots: usize,
        debug: bool,
        capacity: u64,
    ) -> Result<MetaballBuffers> {
        let px = s.pixels();
        let (sky_w, sky_h, sky_px) = match &s.sky {
            Some(p) => load_sky(p)?,
            None => (0, 0, vec![0u32]),
        };
        let entry = entry_bytes(s.list);
        let list_capacity = match s.list {
            ListKind::None | ListKind::Tiles => 0,
            _ => capacity.max(1).min(ctx.max_storage_range() / entry),
        };
        // Buffers a configuration does not use stay bound, at a token size.
        let only = |used: bool, bytes: u64| if used { bytes } else { 16 };
        let (sbuf, abuf) = (s.list == ListKind::Sbuffer, s.list == ListKind::Abuffer);
        // Every buffer is guarded: a failure halfway releases the ones made before it.
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let params = buf("render params", std::mem::size_of::<RenderParams>() as u64)?;
        let offsets = buf("sbuffer offsets", only(sbuf, (px + 1) * 4))?;
        let list = buf("sbuffer list", only(sbuf, list_capacity * 4))?;
        let heads = buf("abuffer heads", only(abuf, px * 4))?;
        let nodes = buf("abuffer nodes", only(abuf, list_capacity * 8))?;
        let stats = buf("render stats", GpuStats::BUFFER_SIZE)?;
        let pixels = buf("render pixels", px * 4)?;
        let debug_buf = buf("render debug", only(debug, px * 16))?;
        let sky = buf("sky image", sky_px.len() as u64 * 4)?;
        let depths = buf(
            "metaball depths",
            only(s.sorts_lists() || s.bins_tiles(), n_capacity.max(1) * 4),
        )?;
        let opaque = buf("opaque layer", only(s.opaque, px * 8))?;
        let scene_depth = buf("scene depth", only(s.opaque, px * 4))?;
        // "render ...": the renderer's own fixed-size buffers (neither per particle nor per pixel).
        let occupancy = buf(
            "render occupancy grid",
            only(s.has_secondary_rays(), OCCUPANCY_BYTES),
        )?;
        let surface = match s.marches() {
            true => None,
            false => {
                let fluid = s.fluid.as_ref().ok_or_else(|| {
                    Error::Param(format!(
                        "--surface {} needs the particles' fluid (spacing, h, bounds)",
                        s.surface.as_str()
                    ))
                })?;
                Some(crate::render::surface::SurfaceBuffers::new(
                    ctx,
                    s.surface,
                    fluid,
                    s.mesh_cell,
                    (s.width, s.height),
                    n_capacity,
                )?)
            }
        };
        let surface = Guard::new(ctx, surface);
        let tiles = Guard::new(
            ctx,
            super::tiles::TileBuffers::new(ctx, s, scan, n_capacity, capacity)?,
        );
        let bounds = Guard::new(ctx, BoundsBuffers::new(ctx, n_capacity.max(1))?);
        let scan = Guard::new(ctx, scan.scratch(ctx, if sbuf { px + 1 } else { 0 })?);
        let mut stats_readback = Guard::new(ctx, Vec::new());
        let mut pixels_readback = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            stats_readback.push(ctx.create_buffer(
                "render stats readback",
                GpuStats::BUFFER_SIZE,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
            pixels_readback.push(ctx.create_buffer(
                "render pixels readback",
                px * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        let mut b = Guard::new(
            ctx,
            MetaballBuffers {
                params: params.take(),
                offsets: offsets.take(),
                list: list.take(),
                heads: heads.take(),
                nodes: nodes.take(),
                stats: stats.take(),
                pixels: pixels.take(),
                debug: debug_buf.take(),
                sky: sky.take(),
                depths: depths.take(),
                opaque: opaque.take(),
                scene_depth: scene_depth.take(),
                occupancy: occupancy.take(),
                sky_size: (sky_w, sky_h),
                bounds: bounds.take(),
                scan: scan.take(),
                stats_readback: stats_readback.take(),
                pixels_readback: pixels_readback.take(),
                list_capacity,
                debug_on: debug,
                surface: surface.take(),
                tiles: tiles.take(),
            },
        );
        ctx.upload(&mut b.sky, 0, &sky_px)?;
        Ok(b.take())
    }

    /// Reallocate the list for `needed` entries: exactly (S-buffer) or with 25% headroom
    /// (A-buffer, whose count is only known after the pass).
    pub fn grow(&mut self, ctx: &Context, list: ListKind, needed: u64) -> Result<()> {
        let b = self;
        let fits = ctx.max_storage_range() / entry_bytes(list);
        if needed > fits {
            return Err(Error::Memory(format!(
                "the {} needs {needed} entries, more than one storage binding addresses on this \
                 device ({fits}); lower the resolution, the metaball radius or the particle count",
                list.as_str()
            )));
        }
        match list {
            ListKind::None | ListKind::Tiles => Ok(()),
            // The new list is made before the old one goes, so a failed allocation leaves
            // the buffers as they were.
            ListKind::Sbuffer => {
                let fresh = ctx.storage_buffer("sbuffer list", needed.max(1) * 4)?;
                let mut old = std::mem::replace(&mut b.list, fresh);
                ctx.destroy_buffer(&mut old);
                b.list_capacity = needed.max(1);
                Ok(())
            }
            ListKind::Abuffer => {
                let cap = (needed + needed / 4 + 1).min(fits);
                let fresh = ctx.storage_buffer("abuffer nodes", cap * 8)?;
                let mut old = std::mem::replace(&mut b.nodes, fresh);
                ctx.destroy_buffer(&mut old);
                b.list_capacity = cap;
                Ok(())
            }
        }
    }
}

crate::impl_destroy!(MetaballBuffers);
