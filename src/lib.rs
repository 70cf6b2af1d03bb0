//! fluidform: a Rust + Vulkan research testbed for liquid characters. This crate is the
//! application: the command line (`config`), scenes, `run` and the window, benchmarks,
//! experiments and their reports. The layers below are crates of their own: the GPU layer
//! (`fluidform-gpu`, src/gpu) and the simulation and rendering (`fluidform-sim`, src/sim),
//! re-exported here under their module names. See README.md and docs/.
pub mod animation;
pub mod bench;
pub mod config;
pub mod experiment;
pub mod export;
pub mod progress;
pub mod report;
pub mod run;
pub mod scene;
pub mod settings;
pub mod shaders;
pub mod window;

pub use fluidform_gpu as gpu;
pub use fluidform_gpu::{error, gpu_interface, impl_destroy, kinds, primitives, Error, Result};
pub use fluidform_sim::{character, control, emission, isosurface, psys, render, sph};
