//! Rendering passes. For now: the camera and the particle (billboard sphere) view.
pub mod camera;
pub mod metaball;
pub mod points;

pub use camera::Camera;
pub use points::PointsView;
