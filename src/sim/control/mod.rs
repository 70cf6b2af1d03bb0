//! Control particles (seed 000, section 3): placement inside a character's mesh, binding to
//! its skeleton, the inside tests they need, the control force (an SPH hook), targets and
//! their timeline, and the fidelity metrics (with the mesh distance they use).
mod kinds;
pub use kinds::{Adaptive, BoneWeights, ControlMotion, ControlPreset, Deficit, Placement};
pub mod binding;
pub mod cache;
pub mod fidelity;
pub mod fits;
pub mod force;
pub mod grid;
pub mod interface;
pub mod mesh_distance;
pub mod metrics;
mod metrics_worker;
pub mod morph_bind;
pub mod passes;
pub mod placement;
pub mod rays;
pub mod settings;
pub mod target;
pub mod timeline;
// The inside tests live beside the mesh checks (thickness needs them too).
pub use crate::character::{inside, winding};
