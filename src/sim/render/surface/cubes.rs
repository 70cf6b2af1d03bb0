//! Marching cubes on the GPU over the SPH density (as splashsurf meshes particle fluids):
//! the particles' poly6 density on a grid over the fluid's bounds, every cell's triangles
//! appended to a soup whose count drives an indirect draw, and the soup rasterised into
//! the G-buffer in two passes (nearest depth and thickness, then the nearest fragment's
//! interpolated normal). Checked against `crate::isosurface::march` on the same grid.
use super::{Rec, Scales, SurfaceIo};
use crate::error::Result;
use crate::gpu::target::begin_empty_rendering;
use crate::gpu::track::BufferUse;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{
    ComputePipeline, Context, GraphicsPipeline, GraphicsStates, Guard, ScopeKey, Scopes,
};

/// The mesh surface's timestamp scopes, inside the frame's rendering scope.
pub const DENSITY_SCOPE: ScopeKey = ScopeKey::new("render/density");
pub const CELLS_SCOPE: ScopeKey = ScopeKey::new("render/cells");
pub const RASTER_SCOPE: ScopeKey = ScopeKey::new("render/raster");

type Graphics = GraphicsPipeline<SurfaceIo>;

crate::gpu::compute_pass!(pub DENSITY: SurfaceIo, Scales = "density", "render/surface/density.comp");
crate::gpu::compute_pass!(pub CELLS: SurfaceIo, Scales = "cells", "render/surface/cells.comp");
crate::gpu::graphics_pass!(
    /// Nearest depth and thickness.
    pub MESH_DEPTH: SurfaceIo, Scales = "mesh depth", "render/surface/mesh.vert", "render/surface/mesh.frag", "PASS" = "0"
);
crate::gpu::graphics_pass!(
    /// The nearest fragment's interpolated normal.
    pub MESH_NORMALS: SurfaceIo, Scales = "mesh normals", "render/surface/mesh.vert", "render/surface/mesh.frag", "PASS" = "1"
);

pub struct Cubes {
    density: ComputePipeline<SurfaceIo>,
    cells: ComputePipeline<SurfaceIo>,
    /// PASS 0: depth and thickness; PASS 1: normals.
    raster: [Graphics; 2],
}

impl Cubes {
    pub fn new(ctx: &Context) -> Result<Self> {
        let storage = GraphicsStates::STORAGE_ONLY;
        let density = Guard::new(ctx, DENSITY.pipeline(ctx, &Scales, 64, &[])?);
        let cells = Guard::new(ctx, CELLS.pipeline(ctx, &Scales, 64, &[])?);
        let depth = Guard::new(ctx, MESH_DEPTH.pipeline(ctx, &Scales, storage)?);
        let normals = Guard::new(ctx, MESH_NORMALS.pipeline(ctx, &Scales, storage)?);
        Ok(Self {
            density: density.take(),
            cells: cells.take(),
            raster: [depth.take(), normals.take()],
        })
    }

    pub(super) fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        r: &Rec,
    ) -> Result<()> {
        let (bufs, push, b) = (&r.bufs, &r.push, r.b);
        {
            let _scope = scopes.open(ctx, cmd, DENSITY_SCOPE.scope());
            ctx.fill(cmd, &b.grid, 0);
            // The draw's arguments, then the box of nodes reached (empty).
            let m = u32::MAX;
            ctx.update(cmd, &b.args, 0, &[0u32, 1, 0, 0, m, m, m, 0, 0, 0]);
            self.density.dispatch(ctx, cmd, bufs, push, r.n as u64);
        }
        {
            let _scope = scopes.open(ctx, cmd, CELLS_SCOPE.scope());
            self.cells.dispatch(ctx, cmd, bufs, push, b.shape.cells());
        }
        {
            let _scope = scopes.open(ctx, cmd, RASTER_SCOPE.scope());
            ctx.fill(cmd, &b.zbits, u32::MAX);
            ctx.fill(cmd, &b.thick, 0);
            ctx.fill(cmd, &b.gbuf, 0);
            let (w, h) = b.size;
            for pass in &self.raster {
                pass.prepare(ctx, cmd, bufs);
                ctx.prepare_draws(cmd, &[BufferUse::indirect(b.args.raw)]);
                begin_empty_rendering(ctx, cmd, w, h);
                pass.bind(ctx, cmd, bufs, push);
                ctx.draw_indirect(cmd, &b.args, 0);
                ctx.end_rendering(cmd);
            }
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.density.destroy(ctx);
        self.cells.destroy(ctx);
        for p in &mut self.raster {
            p.destroy(ctx);
        }
    }
}
crate::impl_destroy!(Cubes);
