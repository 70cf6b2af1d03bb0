//! fluidform: a Rust + Vulkan research testbed for liquid characters. This crate is the top:
//! the benchmarks, the experiments and their tables, `inspect` and the binary.
//! The layers below are crates of their own: the runs and the window (`fluidform-app`,
//! src/app), the switches, scenes and outputs (`fluidform-setup`, src/setup), the simulation and rendering
//! (`fluidform-sim`, src/sim) and the GPU layer (`fluidform-gpu`, src/gpu), all re-exported
//! here under their module names. See README.md and docs/.
pub mod bench;
pub mod experiment;
pub mod inspect;

pub use fluidform_app::{run, window};
pub use fluidform_gpu as gpu;
pub use fluidform_gpu::{error, gpu_interface, impl_destroy, kinds, primitives, Error, Result};
pub use fluidform_setup::{animation, config, export, progress, report, scene, settings, trace};
pub use fluidform_sim::{character, control, emission, isosurface, orbits, psys, render, sph};
