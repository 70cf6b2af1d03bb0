//! fluidform's setup: what a run is given and what it writes. The command line's switches
//! (`config`) and the settings they become at this edge (`settings`), scene files and the
//! built-in scenes (`scene`), and the output contract (`report`, `export`, `animation`,
//! `progress`). Sits on `fluidform-sim` and `fluidform-gpu`; knows no run, window,
//! benchmark or experiment, which live in the crates above.
pub mod animation;
pub mod config;
pub mod export;
pub mod progress;
pub mod provenance;
pub mod report;
pub mod scene;
pub mod settings;
pub mod trace;

// The lower layers under the names this crate's modules use for them.
pub use fluidform_gpu as gpu;
pub use fluidform_gpu::{error, gpu_interface, impl_destroy, kinds, primitives, Error, Result};
pub use fluidform_sim::{character, control, emission, isosurface, orbits, psys, render, sph};
