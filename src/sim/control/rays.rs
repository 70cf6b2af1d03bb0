//! `--placement rays` on the GPU (scope `place`): the skinned mesh rendered orthographically
//! along +z on a pixel grid at the control spacing (the domain's x-y extent), every
//! fragment's depth and facing kept in per-pixel S-buffer lists (count, scan, fill), each
//! list sorted, and control particles written at the lattice steps inside (signed
//! crossings: overlapping closed parts give their union), redone every frame.
//!
//! The count varies by frame and stays on the GPU: the particles fill [0, count) of a
//! buffer of `capacity`; the rest hold a parking position above the domain (in a layer of
//! the control grid no fluid particle visits), and the passes read the count.
use crate::error::{Error, Result};
use crate::gpu::target::begin_empty_rendering;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{
    Buffer, ComputePipeline, Context, GraphicsPipeline, GraphicsStates, Guard, Scopes,
};
use crate::primitives::scan::{ScanKind, ScanPass, ScanScratch, ScanVariant};
use bytemuck::{Pod, Zeroable};

/// glsl/control/rays.glsl `Push`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct RaysGpuPush {
    pub lo: [f32; 4],
    pub dims: [u32; 4],
    pub capacity: u32,
    pub triangles: u32,
    pub pixels: u32,
    pub pad: u32,
}
const _: () = assert!(std::mem::size_of::<RaysGpuPush>() == 48);

crate::gpu_interface! {
    /// glsl/control/rays.glsl
    pub RaysIo / RaysBufs: "RAY", push RaysGpuPush {
        verts = 0, indices = 1, offsets = 2, frags = 3, emit = 4, out = 5, stats = 6,
    }
}

/// Fragments per pixel the lists hold on average (a character seen along z crosses its
/// surface a few times per pixel; more is reported, never dropped silently).
pub const FRAGMENTS_PER_PIXEL: u64 = 24;

/// Byte offsets in the stats buffer of the totals.
pub const STATS_FRAGMENTS: u64 = 0;
pub const STATS_PARTICLES: u64 = 4;

/// The pixel grid and lattice: domain x-y at `spacing`, z steps over the domain's depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaysGrid {
    pub lo: [f32; 3],
    pub spacing: f32,
    pub dims: [u32; 3],
}

impl RaysGrid {
    pub fn new(lo: [f32; 3], hi: [f32; 3], spacing: f32) -> Result<Self> {
        let n = |k: usize| ((hi[k] - lo[k]) / spacing).ceil().max(1.0) as u64;
        let (w, h, d) = (n(0), n(1), n(2));
        // Lists and scans index pixels with u32, graphics viewports stop at 16384.
        if w > 16384 || h > 16384 || w * h > 1 << 26 {
            return Err(Error::Param(format!(
                "--placement rays: a {w} x {h} pixel grid at spacing {spacing} is too large: raise --control-spacing"
            )));
        }
        Ok(Self {
            lo,
            spacing,
            dims: [w as u32, h as u32, d.min(1 << 24) as u32],
        })
    }

    pub fn pixels(&self) -> u64 {
        self.dims[0] as u64 * self.dims[1] as u64
    }

    /// Lattice point of pixel (i, j) and step k (as the shaders compute it).
    pub fn point(&self, i: u32, j: u32, k: u32) -> glam::Vec3 {
        let s = self.spacing;
        glam::Vec3::new(
            self.lo[0] + (i as f32 + 0.5) * s,
            self.lo[1] + (j as f32 + 0.5) * s,
            self.lo[2] + (k as f32 + 0.5) * s,
        )
    }
}

/// Pipelines and buffers of one target's rays placement.
pub struct RaysPlacer {
    count: GraphicsPipeline<RaysIo>,
    fill: GraphicsPipeline<RaysIo>,
    sort_count: ComputePipeline<RaysIo>,
    emit: ComputePipeline<RaysIo>,
    scan: ScanPass,
    scratch: ScanScratch,
    offsets: Buffer,
    frags: Buffer,
    emit_buf: Buffer,
    pub out: Buffer,
    pub stats: Buffer,
    pub grid: RaysGrid,
    pub capacity: u32,
    frag_capacity: u32,
    /// Where unused slots park (all three coordinates; see the module doc).
    pub park: f32,
}

crate::gpu::graphics_pass!(
    /// Counts each pixel's fragments along z.
    pub RAYS_COUNT: RaysIo, () = "rays count", "control/rays.vert", "control/rays.frag", "PASS" = "0"
);
crate::gpu::graphics_pass!(
    /// Writes each pixel's fragments into its range.
    pub RAYS_FILL: RaysIo, () = "rays fill", "control/rays.vert", "control/rays.frag", "PASS" = "1"
);
crate::gpu::compute_pass!(pub RAYS_SORT: RaysIo, () = "rays sort", "control/rays_count.comp");
crate::gpu::compute_pass!(pub RAYS_EMIT: RaysIo, () = "rays emit", "control/rays_emit.comp");

impl RaysPlacer {
    pub const NAME: crate::gpu::ScopeName = crate::gpu::ScopeName::new("place");

    pub fn new(ctx: &Context, grid: RaysGrid, capacity: u32, park: f32) -> Result<Self> {
        let storage = GraphicsStates::STORAGE_ONLY;
        let count = Guard::new(ctx, RAYS_COUNT.pipeline(ctx, &(), storage)?);
        let fill = Guard::new(ctx, RAYS_FILL.pipeline(ctx, &(), storage)?);
        let sort_count = Guard::new(ctx, RAYS_SORT.pipeline(ctx, &(), 64, &[])?);
        let emit = Guard::new(ctx, RAYS_EMIT.pipeline(ctx, &(), 64, &[])?);
        let scan = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
        let px = grid.pixels();
        let frag_capacity = (px * FRAGMENTS_PER_PIXEL).min(u32::MAX as u64 / 8);
        let scratch = Guard::new(ctx, scan.scratch(ctx, px + 1)?);
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let offsets = buf("rays offsets", (px + 1) * 4)?;
        let frags = buf("rays fragments", frag_capacity * 8)?;
        let emit_buf = buf("rays emit", (px + 1) * 4)?;
        let out = buf("rays control particles", capacity as u64 * 16)?;
        let stats = buf("rays stats", 16)?;
        Ok(Self {
            count: count.take(),
            fill: fill.take(),
            sort_count: sort_count.take(),
            emit: emit.take(),
            scan: scan.take(),
            scratch: scratch.take(),
            offsets: offsets.take(),
            frags: frags.take(),
            emit_buf: emit_buf.take(),
            out: out.take(),
            stats: stats.take(),
            grid,
            capacity,
            frag_capacity: frag_capacity as u32,
            park,
        })
    }

    fn push(&self, triangles: u32) -> RaysGpuPush {
        let g = &self.grid;
        RaysGpuPush {
            lo: [g.lo[0], g.lo[1], g.lo[2], g.spacing],
            dims: [g.dims[0], g.dims[1], g.dims[2], self.frag_capacity],
            capacity: self.capacity,
            triangles,
            pixels: g.pixels() as u32,
            pad: 0,
        }
    }

    /// Record the placement from the skinned mesh (`verts` vec4, written and made visible
    /// to vertex shaders by the caller, `indices` of `triangles` triangles) into `out`,
    /// and the totals into `stats`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        verts: &Buffer,
        indices: &Buffer,
        triangles: u32,
    ) -> Result<()> {
        let px = self.grid.pixels();
        let push = self.push(triangles);
        let bufs = RaysBufs {
            verts,
            indices,
            offsets: &self.offsets,
            frags: &self.frags,
            emit: &self.emit_buf,
            out: &self.out,
            stats: &self.stats,
        };
        {
            let _scope = scopes.open(ctx, cmd, Self::NAME);
            ctx.fill(cmd, &self.offsets, 0);
            ctx.fill(cmd, &self.out, self.park.to_bits());
            let [w, h, _] = self.grid.dims;
            let draw = |p: &GraphicsPipeline<RaysIo>| {
                p.prepare(ctx, cmd, &bufs);
                begin_empty_rendering(ctx, cmd, w, h);
                p.bind(ctx, cmd, &bufs, &push);
                ctx.draw(cmd, 3 * triangles, 1);
                ctx.end_rendering(cmd);
            };
            draw(&self.count);
            let scan = |b: &Buffer| {
                self.scan
                    .record(ctx, cmd, b, b, px + 1, ScanKind::Exclusive, &self.scratch)
            };
            scan(&self.offsets)?;
            ctx.copy(cmd, &self.offsets, px * 4, &self.stats, STATS_FRAGMENTS, 4);
            draw(&self.fill);
            self.sort_count.dispatch(ctx, cmd, &bufs, &push, px);
            scan(&self.emit_buf)?;
            self.emit.dispatch(ctx, cmd, &bufs, &push, px);
            ctx.copy(cmd, &self.emit_buf, px * 4, &self.stats, STATS_PARTICLES, 4);
        }
        Ok(())
    }

    /// Fragments and particles of a frame (from a copy of `stats`) within the capacities,
    /// else what overflowed.
    pub fn check(&self, fragments: u32, particles: u32) -> Result<()> {
        if fragments > self.frag_capacity {
            return Err(Error::Param(format!(
                "--placement rays: {fragments} surface crossings overflow the per-pixel lists ({}): the mesh folds more than {FRAGMENTS_PER_PIXEL} times per pixel on average",
                self.frag_capacity
            )));
        }
        if particles > self.capacity {
            return Err(Error::Param(format!(
                "--placement rays: {particles} control particles overflow the capacity {} (three times the rest pose's): the animation inflates the mesh",
                self.capacity
            )));
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.count.destroy(ctx);
        self.fill.destroy(ctx);
        self.sort_count.destroy(ctx);
        self.emit.destroy(ctx);
        self.scan.destroy(ctx);
        self.scratch.destroy(ctx);
        for b in [
            &mut self.offsets,
            &mut self.frags,
            &mut self.emit_buf,
            &mut self.out,
            &mut self.stats,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(RaysPlacer);
