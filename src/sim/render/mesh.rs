//! A skinned character's mesh drawn shaded or as a wireframe (`--show-mesh`), from the
//! skinning pass's positions and normals, depth-tested in the frame's colour target.
use super::Camera;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, GraphicsPipeline};
use crate::render::ShowMesh;
use bytemuck::{Pod, Zeroable};

crate::gpu::graphics_pass!(pub MESH: MeshIo, () = "mesh", "render/mesh.vert", "render/mesh.frag");
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MeshPush {
    pub view_proj: [[f32; 4]; 4],
    pub eye: [f32; 4],
    /// rgb, w = 1: wireframe.
    pub color: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<MeshPush>() == 96);

crate::gpu_interface! {
    /// glsl/render/mesh.vert, mesh.frag
    pub MeshIo / MeshBufs: "MESH", push MeshPush { pos = 0, nrm = 1, indices = 2 }
}

/// What to draw: skinned vec4 positions and normals, and the triangles' indices.
pub struct MeshDraw<'a> {
    pub pos: &'a Buffer,
    pub nrm: &'a Buffer,
    pub indices: &'a Buffer,
    pub triangles: u32,
}

pub struct MeshView {
    pipeline: GraphicsPipeline<MeshIo>,
    push: MeshPush,
}

/// The character's colour: a warm clay, apart from the blue fluid.
pub const MESH_COLOR: [f32; 3] = [0.85, 0.55, 0.35];

impl MeshView {
    pub fn new(ctx: &Context, cam: &Camera, show: ShowMesh) -> Result<Self> {
        let wire = match show {
            ShowMesh::Shaded => 0.0,
            ShowMesh::Wire => 1.0,
            ShowMesh::Off => return Err(Error::Param("a mesh view with --show-mesh off".into())),
        };
        let [r, g, b] = if wire > 0.0 {
            [0.95, 0.9, 0.3]
        } else {
            MESH_COLOR
        };
        let e = cam.eye;
        Ok(Self {
            pipeline: MESH.pipeline(ctx, &(), super::opaque_states())?,
            push: MeshPush {
                view_proj: cam.view_proj().to_cols_array_2d(),
                eye: [e.x, e.y, e.z, 1.0],
                color: [r, g, b, wire],
            },
        })
    }

    /// Draw from `cam` from now on (the viewer's camera moves).
    pub fn set_camera(&mut self, cam: &Camera) {
        let e = cam.eye;
        self.push.view_proj = cam.view_proj().to_cols_array_2d();
        self.push.eye = [e.x, e.y, e.z, 1.0];
    }

    /// Declare the draw of `m` in the next rendering scope (before it begins).
    pub fn prepare(&self, ctx: &Context, cmd: vk::CommandBuffer, m: &MeshDraw) {
        self.pipeline.prepare(ctx, cmd, &Self::bufs(m));
    }

    fn bufs<'a>(m: &MeshDraw<'a>) -> MeshBufs<'a> {
        MeshBufs {
            pos: m.pos,
            nrm: m.nrm,
            indices: m.indices,
        }
    }

    /// Draw the mesh (inside a rendering scope of a colour + depth target).
    pub fn draw(&self, ctx: &Context, cmd: vk::CommandBuffer, m: &MeshDraw) {
        self.pipeline.bind(ctx, cmd, &Self::bufs(m), &self.push);
        ctx.draw(cmd, 3 * m.triangles, 1);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
crate::impl_destroy!(MeshView);
