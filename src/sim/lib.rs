//! fluidform's simulation and rendering: SPH with its particle store and solvers, the
//! characters (loading, skinning, thickness), control particles, emission, the particle
//! systems, the renderers (metaballs, screen-space fluid, meshes, points) and the CPU
//! isosurface. Sits on `fluidform-gpu`; knows no command line, scene file or run.
pub mod character;
pub mod control;
pub mod emission;
pub mod isosurface;
pub mod non_finite_as_null;
pub mod orbits;
pub mod psys;
pub mod render;
pub mod sph;

// The GPU layer under the names this crate's modules use for it.
pub use fluidform_gpu as gpu;
pub use fluidform_gpu::{error, gpu_interface, impl_destroy, kinds, primitives, Error, Result};
