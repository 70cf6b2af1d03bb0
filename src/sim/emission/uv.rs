//! RenderToUV (seed 002, scope `uv`): the skinned mesh rasterised into its UV layout (the
//! atlas of layout.rs, one draw per part at its scale and offset) at `size` texels, each
//! covered texel holding the world position of its surface point and its layout triangle;
//! the positions of the current and the previous frame are kept (the emitter interpolates
//! between them). Coverage depends on the layout only, so the covered texels are listed
//! once, at creation: mask -> exclusive scan -> compaction, and every random pick from the
//! list lands on the surface.
use super::layout::UvLayout;
use crate::error::{Error, Result};
use crate::gpu::target::begin_empty_rendering;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{
    Buffer, ComputePipeline, Context, GraphicsPipeline, GraphicsStates, Guard, Labels, Scopes,
};
use crate::primitives::scan::{ScanKind, ScanPass, ScanScratch, ScanVariant};
use bytemuck::{Pod, Zeroable};

/// glsl/emission/uv.glsl `Push`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct UvPush {
    pub atlas: [f32; 4],
    pub size: [u32; 4],
}
const _: () = assert!(std::mem::size_of::<UvPush>() == 32);

crate::gpu_interface! {
    /// glsl/emission/uv.glsl
    pub UvIo / UvBufs: "UV", push UvPush {
        verts = 0, uvs = 1, src = 2, pos = 3, flags = 4, valid = 5, owner = 6,
    }
}

/// Largest texture side (graphics viewports).
pub const MAX_SIZE: u32 = 8192;

pub struct UvSurface {
    raster: GraphicsPipeline<UvIo>,
    flags_pass: ComputePipeline<UvIo>,
    compact: ComputePipeline<UvIo>,
    scan: ScanPass,
    scratch: ScanScratch,
    uvs: Buffer,
    src: Buffer,
    flags: Buffer,
    /// Per texel: the one layout triangle that writes it (the lowest covering it), so
    /// overlapping UV islands give every frame the same surface point.
    owner: Buffer,
    /// World positions per texel: `pos[current()]` this frame's, the other the last.
    pub pos: [Buffer; 2],
    /// Covered texel indices, `valid_count` of them.
    pub valid: Buffer,
    pub valid_count: u32,
    pub size: [u32; 2],
    current: usize,
    push: UvPush,
    /// Per part: (atlas rect, first layout triangle, triangles).
    parts: Vec<([f32; 4], u32, u32)>,
}

/// A mesh with triangles and an atlas of `size` texels the device can address.
fn check_size(ctx: &Context, layout: &UvLayout, size: [u32; 2]) -> Result<()> {
    if layout.triangles() == 0 {
        return Err(Error::Param("the emitting mesh has no triangles".into()));
    }
    if size.iter().any(|s| *s == 0 || *s > MAX_SIZE) {
        return Err(Error::Param(format!(
            "UV texture size {}x{} is outside 1..={MAX_SIZE}",
            size[0], size[1]
        )));
    }
    let texels = size[0] as u64 * size[1] as u64;
    if texels * 16 > ctx.max_storage_range() {
        return Err(Error::Memory(format!(
            "a {}x{} UV atlas needs {} bytes per position buffer, more than one storage binding may address on this device ({}); lower --uv-size",
            size[0],
            size[1],
            texels * 16,
            ctx.max_storage_range()
        )));
    }
    Ok(())
}

crate::gpu::graphics_pass!(
    /// Rasterises the UV layout: each covered texel's triangle.
    pub UV: UvIo, () = "uv", "emission/uv.vert", "emission/uv.frag"
);
crate::gpu::compute_pass!(pub UV_FLAGS: UvIo, () = "uv flags", "emission/uv_flags.comp");
crate::gpu::compute_pass!(pub UV_COMPACT: UvIo, () = "uv compact", "emission/uv_compact.comp");

impl UvSurface {
    pub const NAME: crate::gpu::ScopeName = UV.scope();

    /// For `layout` at `size` texels (the layout packed for that size); lists the texels
    /// covered with the mesh at `rest` (its vertex positions). Long because each pass and
    /// buffer is made under its own guard, then the texels are listed once.
    pub fn new(
        ctx: &Context,
        layout: &UvLayout,
        rest: &[glam::Vec3],
        size: [u32; 2],
    ) -> Result<Self> {
        check_size(ctx, layout, size)?;
        let texels = size[0] as u64 * size[1] as u64;
        let raster = Guard::new(ctx, UV.pipeline(ctx, &(), GraphicsStates::STORAGE_ONLY)?);
        let flags_pass = Guard::new(ctx, UV_FLAGS.pipeline(ctx, &(), 64, &[])?);
        let compact = Guard::new(ctx, UV_COMPACT.pipeline(ctx, &(), 64, &[])?);
        let scan = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
        let scratch = Guard::new(ctx, scan.scratch(ctx, texels + 1)?);
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let mut uvs = buf("uv coordinates", layout.uvs.len() as u64 * 8)?;
        let uv: Vec<[f32; 2]> = layout.uvs.iter().map(|u| [u.x, u.y]).collect();
        ctx.upload(&mut uvs, 0, &uv)?;
        let mut src = buf("uv corner vertices", layout.src.len() as u64 * 4)?;
        ctx.upload(&mut src, 0, &layout.src)?;
        let flags = buf("uv flags", (texels + 1) * 4)?;
        let owner = buf("uv texel owners", texels * 4)?;
        let pos0 = buf("uv positions 0", texels * 16)?;
        let pos1 = buf("uv positions 1", texels * 16)?;
        let valid = buf("uv valid texels", texels * 4)?;
        let mut s = Guard::new(
            ctx,
            Self {
                raster: raster.take(),
                flags_pass: flags_pass.take(),
                compact: compact.take(),
                scan: scan.take(),
                scratch: scratch.take(),
                uvs: uvs.take(),
                src: src.take(),
                flags: flags.take(),
                owner: owner.take(),
                pos: [pos0.take(), pos1.take()],
                valid: valid.take(),
                valid_count: 0,
                size,
                current: 0,
                push: UvPush {
                    atlas: [1.0, 1.0, 0.0, 0.0],
                    size: [size[0], size[1], texels as u32, 0],
                },
                parts: layout
                    .parts
                    .iter()
                    .map(|p| (p.rect, p.first, p.count))
                    .collect(),
            },
        );
        // The rest pose's positions: coverage is the UV layout's, whatever the pose.
        let v4: Vec<[f32; 4]> = rest.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        let mut verts = Guard::new(ctx, ctx.storage_buffer("uv rest", v4.len() as u64 * 16)?);
        ctx.upload(&mut verts, 0, &v4)?;
        ctx.one_shot(|cmd| -> Result<()> {
            ctx.fill(cmd, &s.owner, u32::MAX);
            s.raster_into(ctx, cmd, &verts, &s.pos[0], 1); // claim the owners
            s.record(ctx, cmd, &mut Labels, &verts)?;
            s.record_compact(ctx, cmd)
        })??;
        let count: Vec<u32> = ctx.readback(&s.flags, texels * 4, 1)?;
        s.valid_count = count[0];
        if s.valid_count == 0 {
            return Err(Error::Param(format!(
                "the mesh's UV layout covers no texel centre at {}x{}",
                size[0], size[1]
            )));
        }
        Ok(s.take())
    }

    /// Index into `pos` of the latest frame's positions.
    pub fn current(&self) -> usize {
        self.current
    }

    fn bufs<'a>(&'a self, verts: &'a Buffer, pos: &'a Buffer) -> UvBufs<'a> {
        UvBufs {
            verts,
            uvs: &self.uvs,
            src: &self.src,
            owner: &self.owner,
            pos,
            flags: &self.flags,
            valid: &self.valid,
        }
    }

    /// Rasterise the skinned mesh (`verts`: its vertices' positions) into the next
    /// position buffer, which becomes the current one.
    pub fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        verts: &Buffer,
    ) -> Result<()> {
        let next = 1 - self.current;
        {
            let _scope = scopes.open(ctx, cmd, Self::NAME);
            ctx.fill(cmd, &self.pos[next], 0);
            self.raster_into(ctx, cmd, verts, &self.pos[next], 0);
        }
        self.current = next;
        Ok(())
    }

    /// Draw every part into `pos` (mode 0: the owners write; 1: claim the owners).
    fn raster_into(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        verts: &Buffer,
        pos: &Buffer,
        mode: u32,
    ) {
        let bufs = self.bufs(verts, pos);
        self.raster.prepare(ctx, cmd, &bufs);
        begin_empty_rendering(ctx, cmd, self.size[0], self.size[1]);
        for &(rect, first, count) in &self.parts {
            let push = UvPush {
                atlas: rect,
                size: [self.size[0], self.size[1], self.push.size[2], mode],
            };
            self.raster.bind(ctx, cmd, &bufs, &push);
            ctx.draw_range(cmd, 3 * count, 3 * first);
        }
        ctx.end_rendering(cmd);
    }

    /// List the covered texels of the current positions (flags, scan, compaction).
    fn record_compact(&self, ctx: &Context, cmd: vk::CommandBuffer) -> Result<()> {
        let texels = self.push.size[2] as u64;
        let (v, i) = (&self.pos[self.current], &self.uvs);
        // (The vertex buffer is not read by the compute passes.)
        let bufs = self.bufs(i, v);
        self.flags_pass
            .dispatch(ctx, cmd, &bufs, &self.push, texels + 1);
        self.scan.record(
            ctx,
            cmd,
            &self.flags,
            &self.flags,
            texels + 1,
            ScanKind::Exclusive,
            &self.scratch,
        )?;
        self.compact.dispatch(ctx, cmd, &bufs, &self.push, texels);
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.raster.destroy(ctx);
        self.flags_pass.destroy(ctx);
        self.compact.destroy(ctx);
        self.scan.destroy(ctx);
        self.scratch.destroy(ctx);
        let [p0, p1] = &mut self.pos;
        for b in [
            &mut self.uvs,
            &mut self.src,
            &mut self.flags,
            &mut self.owner,
            p0,
            p1,
            &mut self.valid,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(UvSurface);
