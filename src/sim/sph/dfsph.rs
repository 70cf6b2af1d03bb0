//! DFSPH (Bender & Koschier 2015): each solve a projected Jacobi on the signed residual (its
//! kappa may fall, never below 0), warm-started where the particle compresses. The
//! divergence-free solve on the step's start velocities
//! (after the neighbourhoods and densities are new; the paper's end-of-step solve, moved to
//! the next step's start), then the non-pressure forces, then the constant-density solve on
//! the predicted velocities, both warm-started with last step's stiffness, then symplectic
//! Euler (glsl/sph/dfsph.comp, euler.comp). The divergence solve's warm start is part of
//! the factor pass, the prediction part of the density solve's first passes, and each
//! iteration's source pass ends the iteration: a step at 2 + 1 iterations runs 14
//! dispatches from factor to Euler, and each spare iteration recorded 2 empty ones.
use super::pressure::{
    check_iterations, check_range, check_step, Convergence, PassCode, PassDecl, Pipelines,
    PressureSolver, EULER,
};
use super::solver::{SphKey, SphSolver, SphState};
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Context, ScopeName, Scopes};

/// DFSPH's iterations, inside each solve's scope.
const ITERATIONS: ScopeName = ScopeName::new("iterations");
use crate::sph::Solver;

/// DFSPH's neighbour list length: a particle has about 20 neighbours at rest (h = 1.68
/// spacings), 30 compressed by half.
pub const DEFAULT_NEIGHBOR_LIST: u32 = 48;
/// Longest neighbour list.
pub const MAX_NEIGHBOR_LIST: u32 = 256;

/// `[fluid.dfsph]`: when the two solves stop, and the neighbour list.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DfsphParams {
    /// The mean density error the step must leave: the density pass's measured error, not
    /// the solve's own estimate (see `stop_fraction`).
    pub density_error: f32,
    /// The density solve iterates until its own estimate is at most this fraction of
    /// `density_error`: the next step's densities exceed the solve's linear prediction by
    /// about dt^2 (on H100, own step, 2 iterations, every estimate far below a 0.1% target,
    /// the dam break measured 0.096% at 16K, 0.122% at 64K, 0.131% at 256K; solving to
    /// half of it measured 0.092%, 0.092%, 0.089%: results/nvidia-h100-80gb-hbm3/solvers.md).
    pub stop_fraction: f32,
    /// Iterate the divergence solve until the mean compression rate times dt is at most this.
    pub divergence_error: f32,
    /// Iterations each solve takes at most, and the density solve at least.
    pub min_iterations: u32,
    pub max_iterations: u32,
    /// Iterations the divergence solve takes at least (SPlisHSPlasH's 1).
    pub divergence_min_iterations: u32,
    /// A particle with fewer fluid neighbours is left out of the divergence solve (its
    /// source 0: spray and thin sheets, whose divergence the kernel cannot estimate);
    /// default 5/8 of a rest lattice's (20 of the cubic's 32 at 2 spacings, as
    /// SPlisHSPlasH's 20).
    pub min_neighbors: Option<u32>,
    /// Neighbours kept per particle and step (0: none). The solves' iterations then read a
    /// list instead of searching 27 grid cells; a particle with more neighbours is searched
    /// as before (exact; counted in `stats.density_error.list_overflows`).
    pub neighbor_list: u32,
    /// The solver's own step, used when `[fluid]` sets no `cfl`: CFL-limited (cfl h /
    /// v_max) up to `dt_max` seconds (--fluid cfl=..., dt_max=... override it; cfl 0:
    /// fixed steps of `dt`).
    pub cfl: f32,
    pub dt_max: f32,
}

/// DFSPH's own CFL number (of h = 2 spacings, the cubic's support: 0.3 spacings a step).
/// The solve's linear prediction of the density misses by more as the step grows: on the
/// 16K dam break's first 0.2 s at a 0.1% target the density pass measured 0.129% at 0.2
/// and 0.057% at 0.15.
pub const OWN_CFL: f32 = 0.15;

/// DFSPH's largest own step: the 16K dam break's measured mean error at a 0.1% target was
/// 0.057% at 1.33 ms steps, 0.129% at 2 ms, 0.35% at 5 ms (at 8 ms, a resting pool 10 cm
/// deep at 1 cm spacings sat 1.2% over rho0 within h of its walls).
pub const OWN_DT_MAX: f32 = 0.0015;

/// DFSPH's default `stop_fraction`.
pub const STOP_FRACTION: f32 = 0.5;

impl Default for DfsphParams {
    fn default() -> Self {
        Self {
            density_error: 0.001,
            stop_fraction: STOP_FRACTION,
            divergence_error: 0.001,
            min_iterations: 2,
            max_iterations: 100,
            divergence_min_iterations: 1,
            min_neighbors: None,
            neighbor_list: DEFAULT_NEIGHBOR_LIST,
            cfl: OWN_CFL,
            dt_max: OWN_DT_MAX,
        }
    }
}

impl DfsphParams {
    pub fn validate(&self) -> Result<()> {
        check_range("dfsph", "density_error", self.density_error, (1e-6, 0.5))?;
        check_range("dfsph", "stop_fraction", self.stop_fraction, (0.01, 1.0))?;
        let d = self.divergence_error;
        check_range("dfsph", "divergence_error", d, (1e-6, 0.5))?;
        check_iterations("dfsph", self.min_iterations, self.max_iterations)?;
        let least = self.divergence_min_iterations;
        check_iterations("dfsph", least.max(1), self.max_iterations)?;
        if least == 0 {
            return Err(crate::error::Error::Param(
                "fluid.dfsph.divergence_min_iterations must be at least 1".into(),
            ));
        }
        check_step("dfsph", self.cfl, self.dt_max)?;
        if self.neighbor_list > MAX_NEIGHBOR_LIST {
            return Err(crate::error::Error::Param(format!(
                "fluid.dfsph.neighbor_list must be at most {MAX_NEIGHBOR_LIST} (0: off), got {}",
                self.neighbor_list
            )));
        }
        Ok(())
    }

    pub fn convergence(&self) -> Convergence {
        Convergence {
            density_error: self.density_error,
            stop_fraction: self.stop_fraction,
            divergence_error: self.divergence_error,
            min_iterations: self.min_iterations,
            max_iterations: self.max_iterations,
        }
    }
}

const SHADER: &str = "sph/dfsph.comp";

super::pressure::solver_passes!(
    "dfsph",
    /// The passes: each variant with its declaration, in the order that indexes the pipelines.
    enum Pass {
        Factor = PassDecl::new("factor", SHADER, PassCode::Factor)
            .divergence()
            .starts(),
        Forces = PassDecl::new("forces", "sph/forces.comp", PassCode::Forces),
        WarmDensity = PassDecl::new("warm/density", SHADER, PassCode::Warm)
            .starts()
            .predicted(),
        PredictDensity = PassDecl::new("predict/density", SHADER, PassCode::Velocity).predicted(),
        SourceDensity = PassDecl::new("source/density", SHADER, PassCode::Source),
        VelocityDensity = PassDecl::new("velocity/density", SHADER, PassCode::Velocity),
        CheckDensity = PassDecl::new("check/density", SHADER, PassCode::Source).check(),
        VelocityDivergence =
            PassDecl::new("velocity/divergence", SHADER, PassCode::Velocity).divergence(),
        SourceDivergence =
            PassDecl::new("source/divergence", SHADER, PassCode::Source).divergence(),
        CheckDivergence = PassDecl::new("check/divergence", SHADER, PassCode::Source)
            .divergence()
            .check(),
        Euler = EULER,
    }
);

/// One of the two solves after its warm start: its scope, the passes that apply the warm
/// start's change and take the first residual, and an iteration's passes.
struct Solve {
    scope: ScopeName,
    first: [Pass; 2],
    iteration: [Pass; 2],
    divergence: bool,
}

const DIVERGENCE: Solve = Solve {
    scope: super::DIVERGENCE_SCOPE.scope(),
    first: [Pass::VelocityDivergence, Pass::SourceDivergence],
    iteration: [Pass::VelocityDivergence, Pass::CheckDivergence],
    divergence: true,
};

const DENSITY: Solve = Solve {
    scope: super::PRESSURE_SCOPE.scope(),
    first: [Pass::PredictDensity, Pass::SourceDensity],
    iteration: [Pass::VelocityDensity, Pass::CheckDensity],
    divergence: false,
};

pub struct Dfsph(Pipelines);

impl Dfsph {
    pub fn new(ctx: &Context, key: &SphKey) -> Result<Self> {
        Pipelines::new(ctx, Solver::Dfsph, Pass::TABLE, key).map(Self)
    }

    /// One solve after its warm start (the factor pass's or the warm pass's, in `warm`):
    /// the warm start applied, the first residual, the iterations.
    fn solve(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
        (s, warm): (&Solve, Option<Pass>),
    ) -> Result<()> {
        let p = &self.0;
        let mut scopes = scopes.open(ctx, cmd, s.scope);
        let iteration = s.iteration.map(|k| k as usize);
        warm.into_iter()
            .chain(s.first)
            .try_for_each(|k| p.run(ctx, cmd, st, k as usize))?;
        let iterations = (&iteration[..], &[][..]);
        p.solve(
            ctx,
            cmd,
            &mut *scopes,
            st,
            ITERATIONS,
            iterations,
            s.divergence,
        )
    }
}

impl PressureSolver for Dfsph {
    fn kind(&self) -> Solver {
        Solver::Dfsph
    }

    fn iteration_dispatches(&self) -> u32 {
        DENSITY.iteration.len() as u32
    }

    /// In place of the density and forces passes: densities, factors and the step's
    /// neighbour lists, the divergence-free solve, the non-pressure forces (from the lists).
    fn record_forces(
        &self,
        _: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        self.0.scoped(ctx, cmd, scopes, st, Pass::Factor as usize)?;
        self.solve(ctx, cmd, scopes, st, (&DIVERGENCE, None))?;
        self.0.scoped(ctx, cmd, scopes, st, Pass::Forces as usize)
    }

    /// The constant-density solve on the predicted velocities, the positions.
    fn record_solve(
        &self,
        _: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        self.solve(ctx, cmd, scopes, st, (&DENSITY, Some(Pass::WarmDensity)))?;
        self.0.scoped(ctx, cmd, scopes, st, Pass::Euler as usize)
    }

    fn destroy(&mut self, ctx: &Context) {
        self.0.destroy(ctx);
    }
}
