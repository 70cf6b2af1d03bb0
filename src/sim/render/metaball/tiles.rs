//! Per-tile metaball lists, after tile-based splatting renderers: every metaball's pixel
//! rectangle (the billboard's, so raster and compute agree) and depth rank (a depth sort),
//! one key per (tile, metaball) pair, tile << rank_bits | rank, sorted with the project's
//! network sort, then each tile's range and its metaballs gathered in (tile, depth) order.
//! `--list tiles` marches over them; `--build compute` fills the S-buffer from them, each
//! pixel's range already in depth order. Pair overflow is counted, grown and redone.
use super::passes::{
    ListKey, Lists, PIXEL_COUNT, PIXEL_FILL, TILE_BIN, TILE_COUNT, TILE_EMIT, TILE_RANGES,
};
use super::renderer::{MetaballBufs, MetaballIo};
use super::settings::{tile_grid, MetaballSettings};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard, Scopes};
use crate::primitives::scan::{ScanKind, ScanPass, ScanScratch};
use crate::primitives::sort::{Network, NetworkSort};

const BIN_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("bin");
const PAIR_SORT_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("pair sort");
const RANGES_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("ranges");

type Compute = ComputePipeline<MetaballIo>;

/// The pixel-block passes' workgroup: one 8 x 8 block (a tile holds whole blocks).
pub const BLOCK_INVOCATIONS: u32 = 64;

/// Bytes per pair: its key, its metaball, the metaball gathered (xyz, depth).
pub const PAIR_BYTES: u64 = 4 + 4 + 16;
/// Bytes per metaball: rectangle, depth key, index, first pair, depth.
pub const BALL_BYTES: u64 = 8 + 4 + 4 + 4 + 4;

/// The sized buffers of the per-tile lists (token sizes when the frame bins no tiles).
pub struct TileBuffers {
    pub(super) rects: Buffer,
    pub(super) ball_keys: Buffer,
    pub(super) ball_ids: Buffer,
    pub(super) pair_counts: Buffer,
    pub(super) pair_keys: Buffer,
    pub(super) pair_ids: Buffer,
    pub(super) tile_balls: Buffer,
    pub(super) tile_ranges: Buffer,
    pub(super) scan: ScanScratch,
    /// Pairs the buffers hold (0: no tiles).
    pub pair_capacity: u64,
    pub tiles: u64,
}

impl TileBuffers {
    /// Bytes of its buffers now.
    pub fn held_bytes(&self) -> u64 {
        let b = [
            &self.rects,
            &self.ball_keys,
            &self.ball_ids,
            &self.pair_counts,
            &self.pair_keys,
            &self.pair_ids,
            &self.tile_balls,
            &self.tile_ranges,
        ];
        b.iter().map(|b| b.size).sum::<u64>() + self.scan.bytes()
    }

    pub fn new(
        ctx: &Context,
        s: &MetaballSettings,
        scan: &ScanPass,
        n_capacity: u64,
        capacity: u64,
    ) -> Result<Self> {
        let used = s.bins_tiles();
        let (_, tiles) = tile_grid(s);
        // Tiles: the caller's first capacity; compute-built S-buffers: the usual guess.
        // Overflow grows it to what a frame needs.
        let pairs = match (used, s.list) {
            (false, _) => 0,
            (true, crate::render::ListKind::Tiles) => capacity.max(1),
            (true, _) => first_pairs(s, n_capacity),
        };
        let only = |bytes: u64| if used { bytes.max(16) } else { 16 };
        let n = n_capacity.max(1);
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let rects = buf("tile rects", only(n * 8))?;
        let ball_keys = buf("tile depth keys", only(n * 4))?;
        let ball_ids = buf("tile depth order", only(n * 4))?;
        let pair_counts = buf("tile pair starts", only((n + 1) * 4))?;
        let pair_keys = buf("tile pair keys", only(pairs * 4))?;
        let pair_ids = buf("tile pair metaballs", only(pairs * 4))?;
        let tile_balls = buf("tile metaballs", only(pairs * 16))?;
        let tile_ranges = buf("tile ranges", only(tiles * 8))?;
        let scan = scan.scratch(ctx, if used { n + 1 } else { 0 })?;
        Ok(Self {
            rects: rects.take(),
            ball_keys: ball_keys.take(),
            ball_ids: ball_ids.take(),
            pair_counts: pair_counts.take(),
            pair_keys: pair_keys.take(),
            pair_ids: pair_ids.take(),
            tile_balls: tile_balls.take(),
            tile_ranges: tile_ranges.take(),
            scan,
            pair_capacity: pairs,
            tiles: if used { tiles } else { 0 },
        })
    }

    /// Room for `needed` pairs with 25% headroom (the count changes as the fluid moves).
    /// The new buffers are made before the old ones go: a failure leaves them as they were.
    pub fn grow(&mut self, ctx: &Context, needed: u64) -> Result<()> {
        let fits = ctx.max_storage_range() / 16;
        if needed > fits {
            return Err(Error::Memory(format!(
                "the tiles need {needed} (tile, metaball) pairs, more than one storage binding \
                 addresses on this device ({fits}); use a larger --tile, a smaller frame or \
                 fewer particles"
            )));
        }
        let cap = (needed + needed / 4 + 1).min(fits);
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let keys = buf("tile pair keys", cap * 4)?;
        let ids = buf("tile pair metaballs", cap * 4)?;
        let balls = buf("tile metaballs", cap * 16)?;
        for (old, fresh) in [
            (&mut self.pair_keys, keys),
            (&mut self.pair_ids, ids),
            (&mut self.tile_balls, balls),
        ] {
            let mut gone = std::mem::replace(old, fresh.take());
            ctx.destroy_buffer(&mut gone);
        }
        self.pair_capacity = cap;
        Ok(())
    }

    /// Bytes the tile structures of a frame with `pairs` pairs and `n` metaballs use.
    pub fn bytes(&self, pairs: u64, n: u64) -> u64 {
        pairs * PAIR_BYTES + self.tiles * 8 + n * BALL_BYTES
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.rects,
            &mut self.ball_keys,
            &mut self.ball_ids,
            &mut self.pair_counts,
            &mut self.pair_keys,
            &mut self.pair_ids,
            &mut self.tile_balls,
            &mut self.tile_ranges,
        ] {
            ctx.destroy_buffer(b);
        }
        self.scan.destroy(ctx);
    }
}

crate::impl_destroy!(TileBuffers);

/// The passes that bin metaballs into tiles, and fill a compute-built S-buffer from them.
pub struct TilePasses {
    bin: Compute,
    count: Compute,
    emit: Compute,
    ranges: Compute,
    sort: NetworkSort,
    /// --build compute: the S-buffer's per-pixel count and fill.
    pixels: Option<(Compute, Compute)>,
}

impl TilePasses {
    pub fn new(ctx: &Context, s: &MetaballSettings) -> Result<Self> {
        let key = Lists(ListKey::of(s));
        let g = |p: Result<Compute>| p.map(|p| Guard::new(ctx, p));
        let bin = g(TILE_BIN.pipeline(ctx, &key, 64, &[]))?;
        let count = g(TILE_COUNT.pipeline(ctx, &key, 64, &[]))?;
        let emit = g(TILE_EMIT.pipeline(ctx, &key, 64, &[]))?;
        let ranges = g(TILE_RANGES.pipeline(ctx, &key, 64, &[]))?;
        let pixels = match s.list {
            crate::render::ListKind::Sbuffer => {
                let key = Lists(ListKey::of(s));
                Some((
                    g(PIXEL_COUNT.pipeline(ctx, &key, BLOCK_INVOCATIONS, &[]))?,
                    g(PIXEL_FILL.pipeline(ctx, &key, BLOCK_INVOCATIONS, &[]))?,
                ))
            }
            _ => None,
        };
        let sort = NetworkSort::new(ctx, Network::Bitonic)?;
        Ok(Self {
            bin: bin.take(),
            count: count.take(),
            emit: emit.take(),
            ranges: ranges.take(),
            sort,
            pixels: pixels.map(|(c, f)| (c.take(), f.take())),
        })
    }

    /// Record the per-tile lists of `n` metaballs (scopes "bin", "pair sort", "ranges").
    #[allow(clippy::too_many_arguments)]
    pub fn record_bins(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        scan: &ScanPass,
        t: &TileBuffers,
        bufs: &MetaballBufs,
        n: u64,
    ) -> Result<()> {
        {
            let _scope = scopes.open(ctx, cmd, BIN_SCOPE);
            ctx.fill(cmd, &t.tile_ranges, 0);
            ctx.fill(cmd, &t.pair_keys, u32::MAX);
            self.bin.dispatch(ctx, cmd, bufs, &(), n);
            self.sort.record(ctx, cmd, &t.ball_keys, &t.ball_ids, n)?;
            self.count.dispatch(ctx, cmd, bufs, &(), n + 1);
            let counts = &t.pair_counts;
            scan.record(
                ctx,
                cmd,
                counts,
                counts,
                n + 1,
                ScanKind::Exclusive,
                &t.scan,
            )?;
            self.emit.dispatch(ctx, cmd, bufs, &(), n);
        }
        {
            let _scope = scopes.open(ctx, cmd, PAIR_SORT_SCOPE);
            self.sort
                .record(ctx, cmd, &t.pair_keys, &t.pair_ids, t.pair_capacity)?;
        }
        {
            let _scope = scopes.open(ctx, cmd, RANGES_SCOPE);
            self.ranges.dispatch(ctx, cmd, bufs, &(), t.pair_capacity);
        }
        Ok(())
    }

    /// Record the compute-built S-buffer's per-pixel count (the caller then scans it), or
    /// with `fill` its fill, each range in depth order.
    pub fn record_pixels(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        bufs: &MetaballBufs,
        s: &MetaballSettings,
        fill: bool,
    ) {
        if let Some((count, filler)) = &self.pixels {
            let pass = if fill { filler } else { count };
            pass.dispatch_groups(ctx, cmd, bufs, &(), blocks(s));
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for p in [
            &mut self.bin,
            &mut self.count,
            &mut self.emit,
            &mut self.ranges,
        ] {
            p.destroy(ctx);
        }
        if let Some((c, f)) = &mut self.pixels {
            c.destroy(ctx);
            f.destroy(ctx);
        }
        self.sort.destroy(ctx);
    }
}

crate::impl_destroy!(TilePasses);

/// A first guess at a frame's pairs: a few tiles per metaball.
pub fn first_pairs(s: &MetaballSettings, n_capacity: u64) -> u64 {
    n_capacity * 4 + tile_grid(s).1
}

/// Workgroups of the 8 x 8 pixel-block passes (the pixel lists, the tiles' march).
pub fn blocks(s: &MetaballSettings) -> u64 {
    s.width.div_ceil(8) as u64 * s.height.div_ceil(8) as u64
}
