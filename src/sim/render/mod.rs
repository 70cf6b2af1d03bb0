//! Rendering passes: the camera, the particle (billboard sphere) view, the metaball
//! renderer and the character mesh.
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
