//! Position based fluids (Macklin & Mueller 2013): predicted positions from the
//! non-pressure forces, density-constraint iterations (lambda, correction with s_corr,
//! apply) to the density error target or a fixed count, velocities from the positions,
//! then vorticity confinement and XSPH viscosity (glsl/sph/pbf.comp).
use super::pressure::{PassDecl, Pipelines, PressureSolver, LOOP_DENSITY};
use super::solver::{SphSolver, SphState};
use crate::error::Result;
use crate::gpu::{Context, Scopes};
use crate::kinds::Solver;
use ash::vk;

/// The passes, in [`PASSES`] order.
#[derive(Clone, Copy)]
enum Pass {
    Predict,
    Lambda,
    Delta,
    Apply,
    Velocity,
    Vorticity,
    Confine,
    Loop,
}

pub const PASSES: [PassDecl; 8] = [
    ("predict", "sph/pbf.comp", "PASS_PREDICT", false),
    ("lambda", "sph/pbf.comp", "PASS_LAMBDA", false),
    ("delta", "sph/pbf.comp", "PASS_DELTA", false),
    ("apply", "sph/pbf.comp", "PASS_APPLY", false),
    ("velocity", "sph/pbf.comp", "PASS_VELOCITY", false),
    ("vorticity", "sph/pbf.comp", "PASS_VORTICITY", false),
    ("confine", "sph/pbf.comp", "PASS_CONFINE", false),
    LOOP_DENSITY,
];

pub struct Pbf(Pipelines);

impl Pbf {
    pub fn new(ctx: &Context, base: &[(&str, String)]) -> Result<Self> {
        Pipelines::new(ctx, Solver::Pbf, &PASSES, base).map(Self)
    }
}

impl PressureSolver for Pbf {
    fn kind(&self) -> Solver {
        Solver::Pbf
    }

    /// After the forces pass (no viscous force: XSPH replaces it) and the force hooks.
    fn record_solve(
        &self,
        _: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        let p = &self.0;
        p.scoped(ctx, cmd, scopes, st, Pass::Predict as usize)?;
        let body = [Pass::Lambda, Pass::Delta, Pass::Apply].map(|k| k as usize);
        p.solve(
            ctx,
            cmd,
            scopes,
            st,
            "pressure",
            (&body, Pass::Loop as usize),
            false,
        )?;
        p.scoped(ctx, cmd, scopes, st, Pass::Velocity as usize)?;
        if st.fluid.xsph > 0.0 || st.fluid.vorticity > 0.0 {
            scopes.begin(ctx, cmd, "vorticity");
            p.run(ctx, cmd, st, Pass::Vorticity as usize)?;
            p.run(ctx, cmd, st, Pass::Confine as usize)?;
            scopes.end(ctx, cmd);
        }
        Ok(())
    }

    fn destroy(&mut self, ctx: &Context) {
        self.0.destroy(ctx);
    }
}
