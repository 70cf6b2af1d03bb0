//! Weakly compressible SPH after Müller et al. 2003 and Kelager 2006, on the GPU, with
//! switchable neighbour search, boundaries and colliders, and an f64 CPU reference.
pub mod boundary;
pub mod cfl;
pub mod collider;
pub mod cpu;
pub mod cpu_pressure;
pub mod dfsph;
pub mod errors;
pub mod gpu_params;
pub mod health;
pub mod hooks;
pub mod kernel;
pub mod paper_dfsph;
pub mod paper_pbf;
pub mod paper_pcisph;
pub mod params;
pub mod pbf;
pub mod pcisph;
pub mod pressure;
pub mod run;
pub mod setup;
pub mod solver;
pub mod spacing;
pub mod v3;
pub mod wcsph;

pub use params::{Collider, Eos, FluidParams};
pub use setup::{Particles, SphSetup};
pub use solver::{SphSolver, SphState};
