//! PCISPH (Solenthaler & Pajarola 2009): after the non-pressure forces, predict-correct
//! pressure iterations to the density error target, then symplectic Euler
//! (glsl/sph/pcisph.comp, euler.comp).
use super::pressure::{
    check_iterations, check_range, check_step, Convergence, PassCode, PassDecl, Pipelines,
    PressureSolver, EULER,
};
use super::solver::{SphKey, SphSolver, SphState};
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Context, Scopes};
use crate::sph::Solver;

/// `[fluid.pcisph]`: when the predict-correct loop stops.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PcisphParams {
    /// Iterate until the predicted mean density error is at most this (0.001: 0.1%).
    pub density_error: f32,
    /// Iterations each solve takes at least and at most.
    pub min_iterations: u32,
    pub max_iterations: u32,
    /// The solver's own step, used when `[fluid]` sets no `cfl`: CFL-limited (cfl h /
    /// v_max) up to `dt_max` seconds (--fluid cfl=..., dt_max=... override it; cfl 0:
    /// fixed steps of `dt`).
    pub cfl: f32,
    pub dt_max: f32,
}

/// PCISPH's largest own step. On H100 (results/nvidia-h100-80gb-hbm3/solvers.md, the
/// cubic kernel) the 256K dam break flung a particle at 2 ms steps; at 0.5 ms its
/// measured error met the 0.1% target at 16K, 64K and 256K (0.079, 0.095, 0.099%) in 2
/// to 3 iterations, faster per simulated second than 1 ms (6 to 12 iterations) or 2 ms
/// (24 to 34).
pub const OWN_DT_MAX: f32 = 0.0005;

/// PCISPH's own CFL number (of the cubic's 2 spacings), with `OWN_DT_MAX` above.
pub const OWN_CFL: f32 = 0.05;

impl Default for PcisphParams {
    fn default() -> Self {
        Self {
            density_error: 0.001,
            min_iterations: 2,
            max_iterations: 100,
            cfl: OWN_CFL,
            dt_max: OWN_DT_MAX,
        }
    }
}

impl PcisphParams {
    pub fn validate(&self) -> Result<()> {
        check_range("pcisph", "density_error", self.density_error, (1e-6, 0.5))?;
        check_iterations("pcisph", self.min_iterations, self.max_iterations)?;
        check_step("pcisph", self.cfl, self.dt_max)
    }

    pub fn convergence(&self) -> Convergence {
        Convergence {
            density_error: self.density_error,
            stop_fraction: 1.0,
            // No divergence solve: the GPU field keeps the default target.
            divergence_error: 0.001,
            min_iterations: self.min_iterations,
            max_iterations: self.max_iterations,
        }
    }
}

const SHADER: &str = "sph/pcisph.comp";

/// An iteration: the passes up to the one that checks, and the one after it.
const CHECKED: [Pass; 2] = [Pass::Predict, Pass::Pressure];
const REST: [Pass; 1] = [Pass::Accel];

super::pressure::solver_passes!(
    "pcisph",
    /// The passes: each variant with its declaration, in the order that indexes the pipelines.
    enum Pass {
        Factor = PassDecl::new("factor", SHADER, PassCode::Factor).starts(),
        Predict = PassDecl::new("predict", SHADER, PassCode::Predict),
        Pressure = PassDecl::new("pressure", SHADER, PassCode::Pressure).check(),
        Accel = PassDecl::new("accel", SHADER, PassCode::Accel),
        Euler = EULER,
    }
);

pub struct Pcisph(Pipelines);

impl Pcisph {
    pub fn new(ctx: &Context, key: &SphKey) -> Result<Self> {
        Pipelines::new(ctx, Solver::Pcisph, Pass::TABLE, key).map(Self)
    }
}

impl PressureSolver for Pcisph {
    fn kind(&self) -> Solver {
        Solver::Pcisph
    }

    fn iteration_dispatches(&self) -> u32 {
        (CHECKED.len() + REST.len()) as u32
    }

    /// acc = the non-pressure acceleration; the density pass left every pressure at 0.
    fn record_solve(
        &self,
        _: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        let p = &self.0;
        // The factor pass zeroes the pressure acceleration and starts the solve.
        p.scoped(ctx, cmd, scopes, st, Pass::Factor as usize)?;
        let (checked, rest) = (CHECKED.map(|k| k as usize), REST.map(|k| k as usize));
        p.solve(
            ctx,
            cmd,
            scopes,
            st,
            super::PRESSURE_SCOPE.scope(),
            (&checked, &rest),
            false,
        )?;
        p.scoped(ctx, cmd, scopes, st, Pass::Euler as usize)
    }

    fn destroy(&mut self, ctx: &Context) {
        self.0.destroy(ctx);
    }
}
