//! PCISPH (Solenthaler & Pajarola 2009): after the non-pressure forces, predict-correct
//! pressure iterations to the density error target, then symplectic Euler
//! (glsl/sph/pcisph.comp, euler.comp).
use super::pressure::{PassDecl, Pipelines, PressureSolver, EULER, LOOP_DENSITY};
use super::solver::{SphSolver, SphState};
use crate::error::Result;
use crate::gpu::{sync, Context, Scopes};
use crate::kinds::Solver;
use ash::vk;

/// The passes, in [`PASSES`] order.
#[derive(Clone, Copy)]
enum Pass {
    Factor,
    Predict,
    Pressure,
    Accel,
    Loop,
    Euler,
}

pub const PASSES: [PassDecl; 6] = [
    ("factor", "sph/pcisph.comp", "PASS_FACTOR", false),
    ("predict", "sph/pcisph.comp", "PASS_PREDICT", false),
    ("pressure", "sph/pcisph.comp", "PASS_PRESSURE", false),
    ("accel", "sph/pcisph.comp", "PASS_ACCEL", false),
    LOOP_DENSITY,
    EULER,
];

pub struct Pcisph(Pipelines);

impl Pcisph {
    pub fn new(ctx: &Context, base: &[(&str, String)]) -> Result<Self> {
        Pipelines::new(ctx, Solver::Pcisph, &PASSES, base).map(Self)
    }
}

impl PressureSolver for Pcisph {
    fn kind(&self) -> Solver {
        Solver::Pcisph
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
        p.scoped(ctx, cmd, scopes, st, Pass::Factor as usize)?;
        // The pressure acceleration starts at zero.
        let aux2 = st.pressure()?.aux2();
        ctx.barrier(cmd, sync::COMPUTE_READ, sync::TRANSFER_WRITE);
        ctx.fill(cmd, aux2, 0);
        ctx.barrier(cmd, sync::TRANSFER_WRITE, sync::COMPUTE_READ);
        let body = [Pass::Predict, Pass::Pressure, Pass::Accel].map(|k| k as usize);
        p.solve(
            ctx,
            cmd,
            scopes,
            st,
            "pressure",
            (&body, Pass::Loop as usize),
            false,
        )?;
        p.scoped(ctx, cmd, scopes, st, Pass::Euler as usize)
    }

    fn destroy(&mut self, ctx: &Context) {
        self.0.destroy(ctx);
    }
}
