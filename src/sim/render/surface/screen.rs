//! Screen-space fluid (van der Laan, Green & Sainz 2009): particles splatted as spheres
//! into the nearest depth and an additive thickness, a separable bilateral filter of the
//! depth (x, then y), and normals from the smoothed depth into the G-buffer.
use super::{Rec, Scales, SurfaceIo};
use crate::error::Result;
use crate::gpu::target::begin_empty_rendering;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{ComputePipeline, Context, GraphicsPipeline, GraphicsStates, Guard, Scopes};

crate::gpu::graphics_pass!(pub SPLAT: SurfaceIo, Scales = "splat", "render/surface/splat.vert", "render/surface/splat.frag");
crate::gpu::compute_pass!(pub SMOOTH: SurfaceIo, Scales = "smooth", "render/surface/smooth.comp");
crate::gpu::compute_pass!(pub NORMALS: SurfaceIo, Scales = "normals", "render/surface/normals.comp");

pub struct ScreenSpace {
    splat: GraphicsPipeline<SurfaceIo>,
    smooth: ComputePipeline<SurfaceIo>,
    normals: ComputePipeline<SurfaceIo>,
}

impl ScreenSpace {
    pub fn new(ctx: &Context) -> Result<Self> {
        let storage = GraphicsStates::STORAGE_ONLY;
        let splat = Guard::new(ctx, SPLAT.pipeline(ctx, &Scales, storage)?);
        let smooth = Guard::new(ctx, SMOOTH.pipeline(ctx, &Scales, 64, &[])?);
        let normals = Guard::new(ctx, NORMALS.pipeline(ctx, &Scales, 64, &[])?);
        Ok(Self {
            splat: splat.take(),
            smooth: smooth.take(),
            normals: normals.take(),
        })
    }

    pub(super) fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        r: &Rec,
    ) {
        let (bufs, push, b, n) = (&r.bufs, &r.push, r.b, r.n);
        let px = b.pixels;
        {
            let _scope = scopes.open(ctx, cmd, SPLAT.scope());
            ctx.fill(cmd, &b.zbits, u32::MAX);
            ctx.fill(cmd, &b.thick, 0);
            self.splat.prepare(ctx, cmd, bufs);
            let (width, height) = b.size;
            begin_empty_rendering(ctx, cmd, width, height);
            self.splat.bind(ctx, cmd, bufs, push);
            ctx.draw(cmd, 6, n);
            ctx.end_rendering(cmd);
        }
        {
            let _scope = scopes.open(ctx, cmd, SMOOTH.scope());
            for axis in [0.0, 1.0] {
                let mut p = *push;
                p.look[1] = axis;
                self.smooth.dispatch(ctx, cmd, bufs, &p, px);
            }
        }
        {
            let _scope = scopes.open(ctx, cmd, NORMALS.scope());
            self.normals.dispatch(ctx, cmd, bufs, push, px);
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.splat.destroy(ctx);
        self.smooth.destroy(ctx);
        self.normals.destroy(ctx);
    }
}
crate::impl_destroy!(ScreenSpace);
