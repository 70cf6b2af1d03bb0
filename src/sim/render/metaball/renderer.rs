//! The metaball frame: bounds -> billboards into per-pixel lists (S-buffer: count, scan,
//! fill; A-buffer: one pass; none: nothing) -> ray march -> RGBA8 pixels.
//! Lists that overflow their capacity are detected every frame (never dropped silently):
//! the caller grows them (`MetaballBuffers::grow`) and redoes the frame; `render_sync`
//! does both. Sized buffers live in buffers.rs.
use super::buffers::MetaballBuffers;
use super::passes::{
    ListKey, Lists, MarchKey, OccupancyKey, ABUFFER_FILL, COUNT, DEPTHS, FILL, MARCH, OCCUPANCY,
    SORT_LISTS,
};
use super::settings::{MetaballSettings, RenderParams};
use super::stats::{FrameStats, GpuStats};
use super::tiles::{blocks, TilePasses};
use crate::error::{Error, Result};
use crate::gpu::target::begin_empty_rendering;
use crate::gpu::vk;
use crate::gpu::Destroy;
use crate::gpu::Open;
use crate::gpu::{
    Buffer, ComputePipeline, Context, GraphicsPipeline, GraphicsStates, Guard, Labels, Scopes,
};
use crate::primitives::bounds::BoundsPass;
use crate::primitives::scan::{ScanKind, ScanPass, ScanVariant};
use crate::render::surface::{Frame, Surface};
use crate::render::Camera;
use crate::render::{BuildKind, Lanes, ListKind};

const BOUNDS_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("bounds");
const SCAN_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("scan");
const SORT_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("sort");

crate::gpu_interface! {
    /// glsl/render/metaball/common.glsl: every metaball pass declares all of these.
    pub MetaballIo / MetaballBufs: "MB", push () {
        params = 0, centers = 1, bounds = 2, offsets = 3, list = 4, heads = 5, nodes = 6,
        stats = 7, pixels = 8, debug = 9, sky = 10, depths = 11, opaque = 12,
        scene_depth = 13, rects = 14, ball_keys = 15, ball_ids = 16, pair_counts = 17,
        pair_keys = 18, pair_ids = 19, tile_balls = 20, tile_ranges = 21, occupancy = 22,
    }
}

type Compute = ComputePipeline<MetaballIo>;
type Graphics = GraphicsPipeline<MetaballIo>;

pub struct FluidRenderer {
    pub settings: MetaballSettings,
    count: Option<Graphics>,
    fill: Option<Graphics>,
    /// Sorted S-buffer built by raster: every metaball's view depth, then each pixel's
    /// range by it.
    sort: Option<(Compute, Compute)>,
    /// Per-tile lists (tiles, and the S-buffer built in compute from them).
    tiles: Option<TilePasses>,
    /// The metaballs' ray march (none for the other surfaces).
    march: Option<Compute>,
    /// The occupancy grid's build (where the march has secondary rays).
    occupancy: Option<Compute>,
    /// Screen-space fluid or marching cubes instead of the metaballs.
    surface: Option<Surface>,
    pub(super) scan: ScanPass,
    bounds: BoundsPass,
}

impl FluidRenderer {
    pub fn new(ctx: &Context, settings: MetaballSettings) -> Result<Self> {
        settings.validate()?;
        Self::check_ray_lanes(ctx, &settings)?;
        let key = ListKey::of(&settings);
        let storage = GraphicsStates::STORAGE_ONLY;
        let graphics = |p: Result<Graphics>| p.map(|p| Guard::new(ctx, p));
        let (count, fill) = match settings.list {
            _ if !settings.marches() || settings.build == BuildKind::Compute => (None, None),
            ListKind::None | ListKind::Tiles => (None, None),
            ListKind::Sbuffer => (
                Some(graphics(COUNT.pipeline(ctx, &Lists(key), storage))?),
                Some(graphics(FILL.pipeline(ctx, &Lists(key), storage))?),
            ),
            ListKind::Abuffer => (
                None,
                Some(graphics(ABUFFER_FILL.pipeline(ctx, &Lists(key), storage))?),
            ),
        };
        let (march, surface) = match settings.marches() {
            true => (
                Some(MARCH.pipeline(ctx, &MarchKey::of(&settings), 64, &[])?),
                None,
            ),
            false => (
                None,
                Some(Surface::new(ctx, settings.surface, settings.material)?),
            ),
        };
        let march = Guard::new(ctx, march);
        let surface = Guard::new(ctx, surface);
        let occupancy = match settings.has_secondary_rays() {
            true => Some(OCCUPANCY.pipeline(ctx, &OccupancyKey, 64, &[])?),
            false => None,
        };
        let occupancy = Guard::new(ctx, occupancy);
        let tiles = match settings.bins_tiles() {
            true => Some(TilePasses::new(ctx, &settings)?),
            false => None,
        };
        let tiles = Guard::new(ctx, tiles);
        let compute = |p: Result<Compute>| p.map(|p| Guard::new(ctx, p));
        let sort = match settings.sort_pass() {
            true => Some((
                compute(DEPTHS.pipeline(ctx, &Lists(key), 64, &[]))?,
                compute(SORT_LISTS.pipeline(ctx, &Lists(key), 64, &[]))?,
            )),
            false => None,
        };
        let scan = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
        let bounds = BoundsPass::new(ctx)?;
        Ok(Self {
            settings,
            count: count.map(Guard::take),
            fill: fill.map(Guard::take),
            sort: sort.map(|(d, s)| (d.take(), s.take())),
            tiles: tiles.take(),
            march: march.take(),
            occupancy: occupancy.take(),
            surface: surface.take(),
            scan: scan.take(),
            bounds,
        })
    }

    /// Take settings that compile to the same shaders at the same frame size (threshold,
    /// radius, step, refinement, depth, ...), so sweeps over them reuse the pipelines.
    pub fn retune(&mut self, settings: MetaballSettings) -> Result<()> {
        self.check_retune(&settings)?;
        self.settings = settings;
        Ok(())
    }

    /// Whether `settings` need only this renderer's shaders and frame size.
    fn check_retune(&self, settings: &MetaballSettings) -> Result<()> {
        settings.validate()?;
        let same = settings.shader_defines() == self.settings.shader_defines()
            && (settings.build, settings.tile) == (self.settings.build, self.settings.tile)
            && (settings.width, settings.height) == (self.settings.width, self.settings.height)
            && settings.sky == self.settings.sky;
        if !same {
            return Err(Error::Param(
                "retune: these settings need other shaders or another frame size".into(),
            ));
        }
        Ok(())
    }

    /// Buffers for these settings, up to `n_capacity` metaballs and `slots` frames.
    pub fn buffers(
        &self,
        ctx: &Context,
        n_capacity: u64,
        slots: usize,
        debug: bool,
    ) -> Result<MetaballBuffers> {
        let first = match self.settings.list {
            // A few tiles per metaball.
            ListKind::Tiles => super::tiles::first_pairs(&self.settings, n_capacity),
            _ => self.settings.pixels() * 4,
        };
        self.buffers_with_capacity(ctx, n_capacity, slots, debug, first)
    }

    /// As `buffers`, with the list's first capacity in entries (tiles: pairs; it grows on
    /// overflow).
    pub fn buffers_with_capacity(
        &self,
        ctx: &Context,
        n_capacity: u64,
        slots: usize,
        debug: bool,
        capacity: u64,
    ) -> Result<MetaballBuffers> {
        let s = &self.settings;
        MetaballBuffers::with_capacity(ctx, s, &self.scan, n_capacity, slots, debug, capacity)
    }

    fn bufs<'a>(&self, b: &'a MetaballBuffers, centers: &'a Buffer) -> MetaballBufs<'a> {
        MetaballBufs {
            params: &b.params,
            centers,
            bounds: &b.bounds.result,
            offsets: &b.offsets,
            list: &b.list,
            heads: &b.heads,
            nodes: &b.nodes,
            stats: &b.stats,
            pixels: &b.pixels,
            debug: &b.debug,
            sky: &b.sky,
            depths: &b.depths,
            opaque: &b.opaque,
            scene_depth: &b.scene_depth,
            rects: &b.tiles.rects,
            ball_keys: &b.tiles.ball_keys,
            ball_ids: &b.tiles.ball_ids,
            pair_counts: &b.tiles.pair_counts,
            pair_keys: &b.tiles.pair_keys,
            pair_ids: &b.tiles.pair_ids,
            tile_balls: &b.tiles.tile_balls,
            tile_ranges: &b.tiles.tile_ranges,
            occupancy: &b.occupancy,
        }
    }

    /// Record a frame of `n` metaballs at `centers` (vec4 xyz, written and made visible to
    /// compute and vertex shaders by the caller) into `b.pixels` and this slot's readbacks.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        b: &MetaballBuffers,
        centers: &Buffer,
        n: u32,
        cam: &Camera,
        slot: usize,
    ) -> Result<()> {
        self.record_picture_as(&self.settings, ctx, cmd, scopes, b, centers, n, cam)?;
        self.record_readback(ctx, cmd, b, slot);
        Ok(())
    }

    /// `record` with settings that need this renderer's shaders and frame size (as
    /// `retune` checks): one renderer serves several table cells, timed interleaved.
    #[allow(clippy::too_many_arguments)]
    pub fn record_as(
        &self,
        s: &MetaballSettings,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        b: &MetaballBuffers,
        centers: &Buffer,
        n: u32,
        cam: &Camera,
    ) -> Result<()> {
        self.check_retune(s)?;
        self.record_picture_as(s, ctx, cmd, scopes, b, centers, n, cam)?;
        self.record_readback(ctx, cmd, b, 0);
        Ok(())
    }

    /// `record` without the readbacks: the picture in `b.pixels` (and `b.scene_depth` with
    /// the opaque layer), for layers drawn over it before `record_readback`.
    #[allow(clippy::too_many_arguments)]
    pub fn record_picture(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        b: &MetaballBuffers,
        centers: &Buffer,
        n: u32,
        cam: &Camera,
    ) -> Result<()> {
        self.record_picture_as(&self.settings, ctx, cmd, scopes, b, centers, n, cam)
    }

    #[allow(clippy::too_many_arguments)]
    fn record_picture_as(
        &self,
        s: &MetaballSettings,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        b: &MetaballBuffers,
        centers: &Buffer,
        n: u32,
        cam: &Camera,
    ) -> Result<()> {
        let (w, h) = (s.width, s.height);
        let px = s.pixels();
        if (s.sorts_lists() || s.bins_tiles()) && n as u64 * 4 > b.depths.size {
            return Err(Error::Param(format!(
                "{n} metaballs: the buffers were made for {}",
                b.depths.size / 4
            )));
        }
        if s.bins_tiles() {
            super::settings::check_pair_keys(s, n)?;
        }
        let pairs = b.tiles.pair_capacity;
        let params = RenderParams::new(s, cam, n, b.list_capacity, b.sky_size, b.debug_on, pairs);
        ctx.update(cmd, &b.params, 0, &[params]);
        ctx.fill(cmd, &b.stats, 0);
        match s.list {
            ListKind::Sbuffer => ctx.fill(cmd, &b.offsets, 0),
            ListKind::Abuffer => ctx.fill(cmd, &b.heads, u32::MAX),
            ListKind::None | ListKind::Tiles => {}
        }
        if let (Some(surface), Some(sb)) = (&self.surface, &b.surface) {
            let frame = Frame {
                params: &b.params,
                centers,
                stats: &b.stats,
                pixels: &b.pixels,
                sky: &b.sky,
                opaque: &b.opaque,
                scene_depth: &b.scene_depth,
            };
            return surface.record(ctx, cmd, scopes, &frame, sb, n);
        }
        let march = self
            .march
            .as_ref()
            .ok_or_else(|| Error::Param("a renderer without a surface was given a frame".into()))?;
        {
            let _scope = scopes.open(ctx, cmd, BOUNDS_SCOPE);
            self.bounds.record(ctx, cmd, centers, n as u64, &b.bounds)?;
        }
        let bufs = self.bufs(b, centers);
        let draw = |p: &Graphics| {
            p.prepare(ctx, cmd, &bufs);
            begin_empty_rendering(ctx, cmd, w, h);
            p.bind(ctx, cmd, &bufs, &());
            ctx.draw(cmd, 6, n);
            ctx.end_rendering(cmd);
        };
        if let Some(tiles) = &self.tiles {
            tiles.record_bins(ctx, cmd, scopes, &self.scan, &b.tiles, &bufs, n as u64)?;
        }
        let compute_lists = s.list == ListKind::Sbuffer && s.build == BuildKind::Compute;
        if self.count.is_some() || compute_lists {
            {
                let _scope = scopes.open(ctx, cmd, COUNT.scope());
                match (&self.count, &self.tiles) {
                    (Some(count), _) => draw(count),
                    (None, Some(tiles)) => tiles.record_pixels(ctx, cmd, &bufs, s, false),
                    (None, None) => {}
                }
            }
            {
                let _scope = scopes.open(ctx, cmd, SCAN_SCOPE);
                self.scan.record(
                    ctx,
                    cmd,
                    &b.offsets,
                    &b.offsets,
                    px + 1,
                    ScanKind::Exclusive,
                    &b.scan,
                )?;
            }
            ctx.copy(
                cmd,
                &b.offsets,
                px * 4,
                &b.stats,
                GpuStats::SBUFFER_FRAGMENTS_OFFSET,
                4,
            );
        }
        if let Some(fill) = &self.fill {
            {
                let _scope = scopes.open(ctx, cmd, FILL.scope());
                draw(fill);
            }
        } else if let (true, Some(tiles)) = (compute_lists, &self.tiles) {
            {
                let _scope = scopes.open(ctx, cmd, FILL.scope());
                tiles.record_pixels(ctx, cmd, &bufs, s, true);
            }
        }
        let groups = px.div_ceil(march.local_size as u64);
        if let Some((depths, sort)) = &self.sort {
            {
                let _scope = scopes.open(ctx, cmd, SORT_SCOPE);
                let metaball_groups = (n as u64).div_ceil(depths.local_size as u64);
                depths.dispatch_groups(ctx, cmd, &bufs, &(), metaball_groups);
                sort.dispatch_groups(ctx, cmd, &bufs, &(), groups);
            }
        }
        if let (true, Some(occupancy)) = (s.skips_empty(), &self.occupancy) {
            let _scope = scopes.open(ctx, cmd, OCCUPANCY.scope());
            ctx.fill(cmd, &b.occupancy, 0);
            // No metaballs: no header, an empty grid (dims 0), nothing passed over.
            occupancy.dispatch(ctx, cmd, &bufs, &(), n as u64);
        }
        {
            let _scope = scopes.open(ctx, cmd, MARCH.scope());
            // One workgroup per 8 x 8 block (tiles: march.comp stages the block's tile).
            // --ray-lanes N: N invocations a pixel, so N times the groups.
            let march_groups = match (s.list, s.lanes) {
                (ListKind::Tiles, _) | (_, Lanes::Blocks) => blocks(s),
                (_, Lanes::Rows) => groups,
            } * s.ray_lanes as u64;
            march.dispatch_groups(ctx, cmd, &bufs, &(), march_groups);
        }
        Ok(())
    }

    /// Copy the stats and pixels into this slot's readbacks, for the host.
    pub fn record_readback(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        b: &MetaballBuffers,
        slot: usize,
    ) {
        let px = self.settings.pixels();
        ctx.copy(
            cmd,
            &b.stats,
            0,
            &b.stats_readback[slot],
            0,
            GpuStats::BUFFER_SIZE,
        );
        ctx.copy(cmd, &b.pixels, 0, &b.pixels_readback[slot], 0, px * 4);
        ctx.host_reads(cmd, &[&b.stats_readback[slot], &b.pixels_readback[slot]]);
    }

    /// The statistics of the frame last rendered in `slot` (after its fence).
    pub fn frame_stats(&self, b: &MetaballBuffers, slot: usize) -> FrameStats {
        let raw = b.stats_readback[slot].mapped().expect("mapped");
        let (st, serial) = (GpuStats::read(raw), super::stats::Serial::read(raw));
        let px = self.settings.pixels();
        let pairs = st.pairs as u64;
        let tile_bytes = b.tiles.bytes(pairs, b.tiles.rects.size / 8);
        let (fragments, mut list_bytes) = match self.settings.list {
            ListKind::None => (0, 0),
            ListKind::Tiles => (pairs, tile_bytes),
            ListKind::Sbuffer => {
                let f = st.sbuffer_fragments as u64;
                (f, (px + 1) * 4 + f * 4)
            }
            ListKind::Abuffer => {
                let f = st.abuffer_nodes as u64;
                (f, px * 4 + f * 8 + 4)
            }
        };
        if self.settings.sorts_lists() || self.settings.bins_tiles() {
            list_bytes += b.depths.size;
        }
        if self.settings.list == ListKind::Sbuffer && self.settings.bins_tiles() {
            list_bytes += tile_bytes;
        }
        FrameStats {
            fragments,
            longest: st.longest,
            overflow: st.overflow,
            offscreen_samples: st.offscreen_samples,
            budget_pixels: st.budget_pixels,
            list_bytes,
            triangles: st.triangles as u64,
            pairs,
            march: super::stats::MarchCounts::of(&st, &serial),
        }
    }

    /// Render once, growing the list and redoing the frame until nothing overflows.
    /// Returns the statistics and how many redos it took.
    pub fn render_sync(
        &self,
        ctx: &Context,
        b: &mut MetaballBuffers,
        centers: &Buffer,
        n: u32,
        cam: &Camera,
        slot: usize,
    ) -> Result<(FrameStats, u32)> {
        let mut redos = 0;
        loop {
            ctx.one_shot(|cmd| self.record(ctx, cmd, &mut Labels, b, centers, n, cam, slot))??;
            let st = self.frame_stats(b, slot);
            if st.overflow == 0 {
                return Ok((st, redos));
            }
            if redos >= 4 {
                return Err(Error::Memory(format!(
                    "metaball list still overflows after {redos} redos ({} entries needed)",
                    st.fragments
                )));
            }
            self.grow(ctx, b, &st)?;
            redos += 1;
        }
    }

    /// Room for what frame `st` overflowed: list entries, or the mesh's triangles.
    pub fn grow(&self, ctx: &Context, b: &mut MetaballBuffers, st: &FrameStats) -> Result<()> {
        if let Some(sb) = &mut b.surface {
            return sb.grow(ctx, st.triangles);
        }
        if !self.settings.bins_tiles() {
            return b.grow(ctx, self.settings.list, st.fragments);
        }
        // Pairs first: a frame short of pairs also undercounts its pixels' lists.
        if st.pairs > b.tiles.pair_capacity {
            return b.tiles.grow(ctx, st.pairs);
        }
        if self.settings.list == ListKind::Sbuffer && st.fragments > b.list_capacity {
            return b.grow(ctx, ListKind::Sbuffer, st.fragments);
        }
        Ok(())
    }

    /// `--ray-lanes N` marches a ray on N lanes of one subgroup (ballots and shuffles):
    /// refused in one line where the device's subgroup is narrower or lacks them.
    fn check_ray_lanes(ctx: &Context, s: &MetaballSettings) -> Result<()> {
        let (n, info) = (s.ray_lanes, &ctx.info);
        let held = super::settings::ray_lanes_on(info);
        if !s.marches() || held.contains(&n) {
            return Ok(());
        }
        Err(Error::Param(format!(
            "--ray-lanes {n} marches a ray on {n} lanes of one subgroup (ballots and shuffles); \
             this device's subgroups are {} lanes{}: use --ray-lanes {} or less (a ray over \
             workgroup shared memory is not built)",
            info.subgroup_size,
            if info.subgroup_shuffle {
                ""
            } else {
                " without ballots and shuffles"
            },
            held.iter().max().unwrap_or(&1),
        )))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for p in [&mut self.count, &mut self.fill].into_iter().flatten() {
            p.destroy(ctx);
        }
        self.march.destroy(ctx);
        self.occupancy.destroy(ctx);
        self.surface.destroy(ctx);
        self.tiles.destroy(ctx);
        if let Some((d, s)) = &mut self.sort {
            d.destroy(ctx);
            s.destroy(ctx);
        }
        self.scan.destroy(ctx);
        self.bounds.destroy(ctx);
    }
}

crate::impl_destroy!(FluidRenderer);
