//! Rendering passes: the camera, the particle (billboard sphere) view, the fluid renderer
//! (ray-marched metaballs with per-pixel or per-tile lists, screen-space fluid and GPU
//! marching cubes, all shaded by one pass), the character mesh, and an independent f64 ray
//! tracer (`trace`) the shading is checked against.
mod kinds;
pub use kinds::{
    BuildKind, Counters, DensityFn, Lanes, ListKind, MarchKind, Material, Offscreen, RenderKind,
    ShowMesh, SurfaceKind,
};
pub mod camera;
pub mod mesh;
pub mod metaball;
pub mod points;
pub mod surface;
pub mod trace;

pub use camera::Camera;

use crate::gpu::ScopeKey;
/// A frame's rendering scope: every surface's passes are timed inside it.
pub const SCOPE: ScopeKey = ScopeKey::new("render");
pub use points::PointsView;

/// An opaque draw into the frame's colour and depth targets.
pub fn opaque_states() -> crate::gpu::GraphicsStates {
    use crate::gpu::target::{COLOR_FORMAT, DEPTH_FORMAT};
    crate::gpu::GraphicsStates {
        color_format: Some(COLOR_FORMAT),
        depth_format: Some(DEPTH_FORMAT),
        blend: false,
        topology: crate::gpu::vk::PrimitiveTopology::TRIANGLE_LIST,
    }
}
