//! SPH on the GPU after Müller et al. 2003 and Kelager 2006: the particle store, four
//! pressure solvers (weakly compressible, the papers'; predictive-corrective,
//! divergence-free and position-based), switchable kernels and neighbour search,
//! boundaries and colliders, the stepper that plays a scene, and f64 CPU references.
mod kinds;
pub use kinds::{Kernel, Solver};
pub mod boundary;
pub mod cfl;
pub mod collider;
pub mod commands;
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
pub mod setup;
pub mod solver;
pub mod spacing;
pub mod stepper;
pub mod store;
pub mod v3;
pub mod wcsph;

pub use params::{Collider, Eos, FluidParams};

use crate::gpu::ScopeKey;
/// A step's timestamp scope, and those of the pressure solvers' iterations inside it
/// (the incompressible solvers; WCSPH has none).
pub const SCOPE: ScopeKey = ScopeKey::new("sph");
pub const PRESSURE_SCOPE: ScopeKey = ScopeKey::new("sph/pressure");
pub const DIVERGENCE_SCOPE: ScopeKey = ScopeKey::new("sph/divergence");
pub use setup::{Particles, SphSetup};
pub use solver::{SphSolver, SphState};
