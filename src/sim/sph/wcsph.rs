//! Weakly compressible SPH (Müller et al. 2003, Kelager 2006; the papers'): pressure from
//! the equation of state in the density pass, then the base integration. Its passes are
//! `SphSolver`'s own (density, forces, integrate).
use super::pressure::PressureSolver;
use super::solver::{SphSolver, SphState};
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Context, Scopes};
use crate::sph::Solver;

pub struct Wcsph;

impl PressureSolver for Wcsph {
    fn kind(&self) -> Solver {
        Solver::Wcsph
    }

    /// No solve: no pressure buffers.
    fn buffers(&self) -> bool {
        false
    }

    fn record_solve(
        &self,
        base: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        base.record_integrate(ctx, cmd, scopes, st);
        Ok(())
    }

    fn destroy(&mut self, _: &Context) {}
}
