//! fluidform's runs: `run` plays every scene kind frame by frame (headless, or live in a
//! window) and writes the output contract; `window` is the interactive viewer. Sits on
//! `fluidform-setup` (switches, scenes, outputs), `fluidform-sim` and `fluidform-gpu`;
//! knows no benchmark or experiment, which live in the crate above (`fluidform`), so
//! changing one of those recompiles only that crate.
pub mod run;
pub mod window;

// The lower layers under the names this crate's modules use for them.
pub use fluidform_gpu as gpu;
pub use fluidform_gpu::{error, gpu_interface, impl_destroy, kinds, primitives, Error, Result};
pub use fluidform_setup::{animation, config, export, progress, report, scene, settings, trace};
pub use fluidform_sim::{character, control, emission, isosurface, orbits, psys, render, sph};
