//! Position based fluids (Macklin & Mueller 2013): predicted positions from the
//! non-pressure forces, density-constraint iterations (lambda, correction with s_corr,
//! apply) to the density error target or a fixed count, velocities from the positions,
//! then vorticity confinement and XSPH viscosity (glsl/sph/pbf.comp).
use super::pressure::{
    check_iterations, check_range, check_step, Convergence, PassCode, PassDecl, Pipelines,
    PressureSolver,
};
use super::solver::{SphKey, SphSolver, SphState};
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Context, Scopes};
use crate::sph::Solver;

const VORTICITY_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("vorticity");

/// `[fluid.pbf]`: the constraint iterations, relaxation, tensile correction, XSPH and
/// vorticity confinement.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PbfParams {
    /// Iterate until the mean density error is at most this (unless `iterations` is set).
    pub density_error: f32,
    /// Iterations each solve takes at least and at most.
    pub min_iterations: u32,
    pub max_iterations: u32,
    /// A fixed iteration count (0: iterate to `density_error`).
    pub iterations: u32,
    /// Constraint relaxation epsilon, relative to a full neighbourhood's gradient sum.
    pub relaxation: f32,
    /// Tensile-instability correction s_corr = -k (W(r) / W(dq h))^n.
    pub scorr_k: f32,
    pub scorr_n: f32,
    pub scorr_dq: f32,
    /// XSPH viscosity c.
    pub xsph: f32,
    /// Vorticity confinement epsilon, m/s (acceleration = epsilon N x omega).
    pub vorticity: f32,
    /// The solver's own step, used when `[fluid]` sets no `cfl`: CFL-limited (cfl h /
    /// v_max) up to `dt_max` seconds (--fluid cfl=..., dt_max=... override it; cfl 0:
    /// fixed steps of `dt`).
    pub cfl: f32,
    pub dt_max: f32,
}

/// PBF's largest own step. On H100 (results/nvidia-h100-80gb-hbm3/solvers.md) at 4 ms
/// (CFL 0.4) the dam break measured 0.103, 0.136 and 0.219% at 16K, 64K and 256K
/// against its 0.1% target; at 2 ms (CFL 0.2) 0.089, 0.087 and 0.104%, and faster per
/// simulated second (5 to 9 iterations a step, against 20 to 25).
pub const OWN_DT_MAX: f32 = 0.002;

/// PBF's own CFL number, with `OWN_DT_MAX` above.
pub const OWN_CFL: f32 = 0.2;

impl Default for PbfParams {
    fn default() -> Self {
        Self {
            density_error: 0.001,
            min_iterations: 2,
            max_iterations: 100,
            iterations: 0,
            relaxation: 0.01,
            scorr_k: 0.1,
            scorr_n: 4.0,
            scorr_dq: 0.2,
            xsph: 0.01,
            vorticity: 0.01,
            cfl: OWN_CFL,
            dt_max: OWN_DT_MAX,
        }
    }
}

impl PbfParams {
    pub fn validate(&self) -> Result<()> {
        for (name, v, range) in [
            ("density_error", self.density_error, (1e-6, 0.5)),
            ("relaxation", self.relaxation, (1e-6, 10.0)),
            ("scorr_k", self.scorr_k, (0.0, 1.0)),
            ("scorr_n", self.scorr_n, (1.0, 8.0)),
            ("scorr_dq", self.scorr_dq, (0.01, 0.99)),
            ("xsph", self.xsph, (0.0, 1.0)),
            ("vorticity", self.vorticity, (0.0, 10.0)),
        ] {
            check_range("pbf", name, v, range)?;
        }
        check_iterations("pbf", self.min_iterations, self.max_iterations)?;
        check_step("pbf", self.cfl, self.dt_max)?;
        if self.iterations > super::params::MAX_ITERATIONS {
            return Err(crate::error::Error::Param(format!(
                "fluid.pbf.iterations must be at most {}, got {}",
                super::params::MAX_ITERATIONS,
                self.iterations
            )));
        }
        Ok(())
    }

    /// A fixed `iterations` count is both bounds.
    pub fn convergence(&self) -> Convergence {
        let (min, max) = match self.iterations {
            0 => (self.min_iterations, self.max_iterations),
            k => (k, k),
        };
        Convergence {
            density_error: self.density_error,
            stop_fraction: 1.0,
            divergence_error: 0.001,
            min_iterations: min,
            max_iterations: max,
        }
    }
}

const SHADER: &str = "sph/pbf.comp";

/// An iteration: the pass that checks, and the ones after it.
const CHECKED: [Pass; 1] = [Pass::Lambda];
const REST: [Pass; 2] = [Pass::Delta, Pass::Apply];

super::pressure::solver_passes!(
    "pbf",
    /// The passes: each variant with its declaration, in the order that indexes the pipelines.
    enum Pass {
        Predict = PassDecl::new("predict", SHADER, PassCode::Predict).starts(),
        Lambda = PassDecl::new("lambda", SHADER, PassCode::Lambda).check(),
        Delta = PassDecl::new("delta", SHADER, PassCode::Delta),
        Apply = PassDecl::new("apply", SHADER, PassCode::Apply),
        Velocity = PassDecl::new("velocity", SHADER, PassCode::Velocity),
        Vorticity = PassDecl::new("vorticity", SHADER, PassCode::Vorticity),
        Confine = PassDecl::new("confine", SHADER, PassCode::Confine),
    }
);

pub struct Pbf(Pipelines);

impl Pbf {
    pub fn new(ctx: &Context, key: &SphKey) -> Result<Self> {
        Pipelines::new(ctx, Solver::Pbf, Pass::TABLE, key).map(Self)
    }
}

impl PressureSolver for Pbf {
    fn kind(&self) -> Solver {
        Solver::Pbf
    }

    fn iteration_dispatches(&self) -> u32 {
        (CHECKED.len() + REST.len()) as u32
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
        p.scoped(ctx, cmd, scopes, st, Pass::Velocity as usize)?;
        if st.fluid.pbf.xsph > 0.0 || st.fluid.pbf.vorticity > 0.0 {
            {
                let _scope = scopes.open(ctx, cmd, VORTICITY_SCOPE);
                p.run(ctx, cmd, st, Pass::Vorticity as usize)?;
                p.run(ctx, cmd, st, Pass::Confine as usize)?;
            }
        }
        Ok(())
    }

    fn destroy(&mut self, ctx: &Context) {
        self.0.destroy(ctx);
    }
}
