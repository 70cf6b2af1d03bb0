//! Particle view: instanced camera-facing sphere impostors from position/colour buffers.
use super::Camera;
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, GraphicsPipeline};
use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PointsPush {
    pub view_proj: [[f32; 4]; 4],
    /// Camera right, w = radius scale.
    pub right: [f32; 4],
    pub up: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<PointsPush>() == 96);

impl PointsPush {
    pub fn from_camera(cam: &Camera, radius_scale: f32) -> Self {
        let (r, u) = cam.axes();
        Self {
            view_proj: cam.view_proj().to_cols_array_2d(),
            right: [r.x, r.y, r.z, radius_scale],
            up: [u.x, u.y, u.z, 0.0],
        }
    }
}

crate::gpu_interface! {
    /// glsl/render/points.vert
    pub PointsIo / PointsBufs: "PTS", push PointsPush { pos = 0, color = 1 }
}

pub struct PointsView {
    pipeline: GraphicsPipeline<PointsIo>,
}

crate::gpu::graphics_pass!(pub POINTS: PointsIo, () = "points", "render/points.vert", "render/points.frag");

impl PointsView {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: POINTS.pipeline(ctx, &(), super::opaque_states())?,
        })
    }

    /// Declare the draw of the particles in the next rendering scope (before it begins).
    pub fn prepare(&self, ctx: &Context, cmd: vk::CommandBuffer, pos: &Buffer, color: &Buffer) {
        self.pipeline.prepare(ctx, cmd, &PointsBufs { pos, color });
    }

    /// Draw `n` particles (inside a rendering scope).
    pub fn draw(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        pos: &Buffer,
        color: &Buffer,
        n: u32,
        push: &PointsPush,
    ) {
        self.pipeline
            .bind(ctx, cmd, &PointsBufs { pos, color }, push);
        ctx.draw(cmd, 6, n);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
crate::impl_destroy!(PointsView);
