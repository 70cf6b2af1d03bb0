//! The SPH choices a run names: the pressure solver and the smoothing kernel.
//! Closed sets (`fluidform_gpu::kinds::Kind`): each parses and prints as its switch spells it.
use fluidform_gpu::switch_enum;

switch_enum!(
    /// SPH pressure solver: weakly compressible (the papers'), or the incompressible
    /// predictive-corrective, divergence-free and position-based ones.
    Solver {
        Wcsph,
        Pcisph,
        Dfsph,
        Pbf
    }
);
switch_enum!(
    /// SPH smoothing kernel, one for densities and pressure gradients alike (src/sim/sph/kernel.rs):
    /// Mueller 2003's poly6 densities with spiky gradients (the thesis's), the cubic
    /// spline, or Wendland's C2.
    Kernel {
        Muller,
        Cubic,
        Wendland
    }
);
