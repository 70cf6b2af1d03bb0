//! The metaball frame: bounds -> billboards into per-pixel lists (S-buffer: count, scan,
//! fill; A-buffer: one pass; none: nothing) -> ray march -> RGBA8 pixels.
//! Lists that overflow their capacity are detected every frame (never dropped silently):
//! the caller grows them (`grow`) and redoes the frame; `render_sync` does both.
use super::settings::{MetaballSettings, RenderParams};
use crate::config::ListKind;
use crate::error::{Error, Result};
use crate::gpu::target::begin_empty_rendering;
use crate::gpu::{
    Buffer, ComputeDesc, ComputePipeline, Context, GraphicsDesc, GraphicsPipeline, Labels,
    MemoryLocation, Scopes,
};
use crate::primitives::bounds::{BoundsBuffers, BoundsPass};
use crate::primitives::scan::{ScanKind, ScanPass, ScanScratch, ScanVariant};
use crate::render::Camera;
use ash::vk;
use serde::Serialize;

const BINDINGS: u32 = 12;
const STATS: u64 = 8;

pub struct MetaballRenderer {
    pub settings: MetaballSettings,
    count: Option<GraphicsPipeline>,
    fill: Option<GraphicsPipeline>,
    /// Sorted S-buffer: every metaball's view depth, then each pixel's range by it.
    sort: Option<(ComputePipeline, ComputePipeline)>,
    march: ComputePipeline,
    scan: ScanPass,
    bounds: BoundsPass,
}

/// Sized buffers: lists for width x height, up to `n_capacity` metaballs, per-slot readbacks.
pub struct MetaballBuffers {
    params: Buffer,
    offsets: Buffer,
    list: Buffer,
    heads: Buffer,
    nodes: Buffer,
    stats: Buffer,
    pub pixels: Buffer,
    debug: Buffer,
    sky: Buffer,
    /// Sorted S-buffer: every metaball's view depth.
    depths: Buffer,
    sky_size: (u32, u32),
    bounds: BoundsBuffers,
    scan: ScanScratch,
    stats_readback: Vec<Buffer>,
    pixels_readback: Vec<Buffer>,
    /// Entries of the S-buffer list or the A-buffer node pool.
    pub list_capacity: u64,
    pub debug_on: bool,
}

/// One frame's list statistics (the thesis's memory column is `list_bytes`).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct FrameStats {
    /// Billboard fragments: list entries of the frame.
    pub fragments: u64,
    /// Longest per-pixel list met by a primary ray.
    pub longest: u32,
    /// List entries that did not fit (the frame must be redone).
    pub overflow: u32,
    /// Secondary-ray samples that left the screen.
    pub offscreen_samples: u32,
    /// Pixels whose rays were cut short: a loop stopped before its own exit condition, as
    /// llvmpipe's loop budget (about 65535 iterations per batch) does. Nonzero: wrong frame.
    pub budget_pixels: u32,
    /// Bytes the list structure needs for this frame (S: offsets + list, sorted: plus the
    /// metaball depths; A: heads + nodes + counter; none: 0).
    pub list_bytes: u64,
}

impl MetaballBuffers {
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
    }

    /// RGBA8 pixels of the frame last rendered in `slot` (after its fence).
    pub fn pixels(&self, slot: usize) -> &[u8] {
        self.pixels_readback[slot].mapped().expect("mapped")
    }
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

impl MetaballRenderer {
    pub fn new(ctx: &Context, settings: MetaballSettings) -> Result<Self> {
        settings.validate()?;
        let list = settings.list_index();
        let common = |extra: Vec<(&'static str, String)>| {
            let mut d = vec![
                ("LIST", list.to_string()),
                ("DENSITY", settings.density.index().to_string()),
                ("MATERIAL", settings.material_index().to_string()),
                ("SORTED", (settings.sorts_lists() as u32).to_string()),
            ];
            d.extend(extra);
            d
        };
        let graphics = |name: &str, pass: u32| -> Result<GraphicsPipeline> {
            let defines = common(vec![("PASS", pass.to_string())]);
            GraphicsPipeline::new(
                ctx,
                &GraphicsDesc {
                    name,
                    vertex: "render/metaball/billboard.vert",
                    fragment: "render/metaball/billboard.frag",
                    defines: &defines,
                    buffers: BINDINGS,
                    push_size: 0,
                    color_format: None,
                    depth_format: None,
                    blend: false,
                    topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                },
            )
        };
        let (count, fill) = match settings.list {
            ListKind::None => (None, None),
            ListKind::Sbuffer => (Some(graphics("count", 0)?), Some(graphics("fill", 1)?)),
            ListKind::Abuffer => (None, Some(graphics("fill", 2)?)),
        };
        let defines = common(vec![]);
        let compute = |name, shader| {
            ComputePipeline::new(
                ctx,
                &ComputeDesc::plain(name, shader, &defines, 64, BINDINGS, 0),
            )
        };
        let march = compute("march", "render/metaball/march.comp")?;
        let sort = if settings.sorts_lists() {
            Some((
                compute("depths", "render/metaball/depths.comp")?,
                compute("sort lists", "render/metaball/sort_lists.comp")?,
            ))
        } else {
            None
        };
        Ok(Self {
            settings,
            count,
            fill,
            sort,
            march,
            scan: ScanPass::new(ctx, ScanVariant::Auto)?,
            bounds: BoundsPass::new(ctx)?,
        })
    }

    pub fn buffers(
        &self,
        ctx: &Context,
        n_capacity: u64,
        slots: usize,
        debug: bool,
    ) -> Result<MetaballBuffers> {
        self.buffers_with_capacity(ctx, n_capacity, slots, debug, self.settings.pixels() * 4)
    }

    /// As `buffers`, with the list's first capacity in entries (it grows on overflow).
    pub fn buffers_with_capacity(
        &self,
        ctx: &Context,
        n_capacity: u64,
        slots: usize,
        debug: bool,
        capacity: u64,
    ) -> Result<MetaballBuffers> {
        let s = &self.settings;
        let px = s.pixels();
        let (sky_w, sky_h, sky_px) = match &s.sky {
            Some(p) => load_sky(p)?,
            None => (0, 0, vec![0u32]),
        };
        let entry = self.entry_bytes();
        let list_capacity = match s.list {
            ListKind::None => 0,
            _ => capacity.max(1).min(ctx.max_storage_range() / entry),
        };
        // Buffers a configuration does not use stay bound, at a token size.
        let only = |used: bool, bytes: u64| if used { bytes } else { 16 };
        let (sbuf, abuf) = (s.list == ListKind::Sbuffer, s.list == ListKind::Abuffer);
        let mut b = MetaballBuffers {
            params: ctx
                .storage_buffer("render params", std::mem::size_of::<RenderParams>() as u64)?,
            offsets: ctx.storage_buffer("sbuffer offsets", only(sbuf, (px + 1) * 4))?,
            list: ctx.storage_buffer("sbuffer list", only(sbuf, list_capacity * 4))?,
            heads: ctx.storage_buffer("abuffer heads", only(abuf, px * 4))?,
            nodes: ctx.storage_buffer("abuffer nodes", only(abuf, list_capacity * 8))?,
            stats: ctx.storage_buffer("render stats", STATS * 4)?,
            pixels: ctx.storage_buffer("render pixels", px * 4)?,
            debug: ctx.storage_buffer("render debug", only(debug, px * 16))?,
            sky: ctx.storage_buffer("sky image", sky_px.len() as u64 * 4)?,
            depths: ctx.storage_buffer(
                "metaball depths",
                only(s.sorts_lists(), n_capacity.max(1) * 4),
            )?,
            sky_size: (sky_w, sky_h),
            bounds: BoundsBuffers::new(ctx, n_capacity.max(1))?,
            scan: self.scan.scratch(ctx, if sbuf { px + 1 } else { 0 })?,
            stats_readback: Vec::new(),
            pixels_readback: Vec::new(),
            list_capacity,
            debug_on: debug,
        };
        ctx.upload(&mut b.sky, 0, &sky_px)?;
        for _ in 0..slots {
            b.stats_readback.push(ctx.create_buffer(
                "render stats readback",
                STATS * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
            b.pixels_readback.push(ctx.create_buffer(
                "render pixels readback",
                px * 4,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        Ok(b)
    }

    /// Bytes of one list entry: an S-buffer metaball index, an A-buffer (index, next) node.
    fn entry_bytes(&self) -> u64 {
        if self.settings.list == ListKind::Abuffer {
            8
        } else {
            4
        }
    }

    /// Reallocate the list for `needed` entries: exactly (S-buffer) or with 25% headroom
    /// (A-buffer, whose count is only known after the pass).
    pub fn grow(&self, ctx: &Context, b: &mut MetaballBuffers, needed: u64) -> Result<()> {
        let fits = ctx.max_storage_range() / self.entry_bytes();
        if needed > fits {
            return Err(Error::Memory(format!(
                "the {} needs {needed} entries, more than one storage binding addresses on this \
                 device ({fits}); lower the resolution, the metaball radius or the particle count",
                self.settings.list.as_str()
            )));
        }
        match self.settings.list {
            ListKind::None => Ok(()),
            ListKind::Sbuffer => {
                ctx.destroy_buffer(&mut b.list);
                b.list = ctx.storage_buffer("sbuffer list", needed.max(1) * 4)?;
                b.list_capacity = needed.max(1);
                Ok(())
            }
            ListKind::Abuffer => {
                let cap = (needed + needed / 4 + 1).min(fits);
                ctx.destroy_buffer(&mut b.nodes);
                b.nodes = ctx.storage_buffer("abuffer nodes", cap * 8)?;
                b.list_capacity = cap;
                Ok(())
            }
        }
    }

    fn infos<'a>(&self, b: &'a MetaballBuffers, centers: &'a Buffer) -> Vec<&'a Buffer> {
        vec![
            &b.params,
            centers,
            &b.bounds.result,
            &b.offsets,
            &b.list,
            &b.heads,
            &b.nodes,
            &b.stats,
            &b.pixels,
            &b.debug,
            &b.sky,
            &b.depths,
        ]
    }

    /// Record a frame of `n` metaballs at `centers` (vec4 xyz) into `b.pixels` and this
    /// slot's readbacks.
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
        let s = &self.settings;
        let (w, h) = (s.width, s.height);
        let px = s.pixels();
        if s.sorts_lists() && n as u64 * 4 > b.depths.size {
            return Err(Error::Param(format!(
                "{n} metaballs: the buffers were made for {}",
                b.depths.size / 4
            )));
        }
        let params = RenderParams::new(s, cam, n, b.list_capacity, b.sky_size, b.debug_on);
        ctx.barrier(cmd);
        unsafe {
            ctx.device
                .cmd_update_buffer(cmd, b.params.raw, 0, bytemuck::bytes_of(&params));
            ctx.device
                .cmd_fill_buffer(cmd, b.stats.raw, 0, vk::WHOLE_SIZE, 0);
            match s.list {
                ListKind::Sbuffer => {
                    ctx.device
                        .cmd_fill_buffer(cmd, b.offsets.raw, 0, vk::WHOLE_SIZE, 0)
                }
                ListKind::Abuffer => {
                    ctx.device
                        .cmd_fill_buffer(cmd, b.heads.raw, 0, vk::WHOLE_SIZE, u32::MAX)
                }
                ListKind::None => {}
            }
        }
        ctx.barrier(cmd);
        scopes.begin(ctx, cmd, "bounds");
        self.bounds.record(ctx, cmd, centers, n as u64, &b.bounds)?;
        scopes.end(ctx, cmd);
        ctx.barrier(cmd);
        let bufs = self.infos(b, centers);
        let draw = |p: &GraphicsPipeline| {
            begin_empty_rendering(ctx, cmd, w, h);
            p.bind(ctx, cmd, &bufs, &());
            unsafe {
                ctx.device.cmd_draw(cmd, 6, n, 0, 0);
                ctx.device.cmd_end_rendering(cmd);
            }
            ctx.barrier(cmd);
        };
        if let Some(count) = &self.count {
            scopes.begin(ctx, cmd, "count");
            draw(count);
            scopes.end(ctx, cmd);
            scopes.begin(ctx, cmd, "scan");
            self.scan.record(
                ctx,
                cmd,
                &b.offsets,
                &b.offsets,
                px + 1,
                ScanKind::Exclusive,
                &b.scan,
            )?;
            scopes.end(ctx, cmd);
            ctx.barrier(cmd);
            // The total (offsets[W*H]) into stats[4] for the readback.
            let region = vk::BufferCopy {
                src_offset: px * 4,
                dst_offset: 16,
                size: 4,
            };
            unsafe {
                ctx.device
                    .cmd_copy_buffer(cmd, b.offsets.raw, b.stats.raw, &[region])
            };
            ctx.barrier(cmd);
        }
        if let Some(fill) = &self.fill {
            scopes.begin(ctx, cmd, "fill");
            draw(fill);
            scopes.end(ctx, cmd);
        }
        let groups = px.div_ceil(self.march.local_size as u64);
        let infos: Vec<_> = bufs.iter().map(|b| b.info()).collect();
        if let Some((depths, sort)) = &self.sort {
            scopes.begin(ctx, cmd, "sort");
            let metaball_groups = (n as u64).div_ceil(depths.local_size as u64);
            depths.dispatch_groups(ctx, cmd, &infos, &(), metaball_groups);
            ctx.barrier(cmd);
            sort.dispatch_groups(ctx, cmd, &infos, &(), groups);
            scopes.end(ctx, cmd);
            ctx.barrier(cmd);
        }
        scopes.begin(ctx, cmd, "march");
        self.march.dispatch_groups(ctx, cmd, &infos, &(), groups);
        scopes.end(ctx, cmd);
        ctx.barrier(cmd);
        let copy = |src: &Buffer, dst: &Buffer, size: u64| unsafe {
            let region = vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size,
            };
            ctx.device.cmd_copy_buffer(cmd, src.raw, dst.raw, &[region]);
        };
        copy(&b.stats, &b.stats_readback[slot], STATS * 4);
        copy(&b.pixels, &b.pixels_readback[slot], px * 4);
        ctx.barrier(cmd);
        Ok(())
    }

    /// The statistics of the frame last rendered in `slot` (after its fence).
    pub fn frame_stats(&self, b: &MetaballBuffers, slot: usize) -> FrameStats {
        let st: &[u32] = bytemuck::cast_slice(b.stats_readback[slot].mapped().expect("mapped"));
        let px = self.settings.pixels();
        let (fragments, mut list_bytes) = match self.settings.list {
            ListKind::None => (0, 0),
            ListKind::Sbuffer => (st[4] as u64, (px + 1) * 4 + st[4] as u64 * 4),
            ListKind::Abuffer => (st[0] as u64, px * 4 + st[0] as u64 * 8 + 4),
        };
        if self.settings.sorts_lists() {
            list_bytes += b.depths.size;
        }
        FrameStats {
            fragments,
            longest: st[1],
            overflow: st[2],
            offscreen_samples: st[3],
            budget_pixels: st[5],
            list_bytes,
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
            self.grow(ctx, b, st.fragments)?;
            redos += 1;
        }
    }

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

    pub fn destroy(&mut self, ctx: &Context) {
        for p in [&mut self.count, &mut self.fill].into_iter().flatten() {
            p.destroy(ctx);
        }
        self.march.destroy(ctx);
        if let Some((d, s)) = &mut self.sort {
            d.destroy(ctx);
            s.destroy(ctx);
        }
        self.scan.destroy(ctx);
        self.bounds.destroy(ctx);
    }
}
