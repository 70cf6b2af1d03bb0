//! PCISPH (Solenthaler & Pajarola 2009): after the non-pressure forces, predict-correct
//! pressure iterations to the density error target, then symplectic Euler
//! (glsl/sph/pcisph.comp, euler.comp).
use super::pressure::PressurePasses;
use super::solver::SphState;
use crate::error::Result;
use crate::gpu::{sync, Context, Scopes};
use ash::vk;

/// The step after the forces pass and the force hooks (acc = non-pressure acceleration;
/// the density pass left every pressure at 0).
pub fn record(
    p: &PressurePasses,
    ctx: &Context,
    cmd: vk::CommandBuffer,
    scopes: &mut dyn Scopes,
    st: &SphState,
) -> Result<()> {
    p.scoped(ctx, cmd, scopes, st, "factor")?;
    // The pressure acceleration starts at zero.
    let aux2 = st.pressure()?.aux2();
    ctx.barrier(cmd, sync::COMPUTE_READ, sync::TRANSFER_WRITE);
    ctx.fill(cmd, aux2, 0);
    ctx.barrier(cmd, sync::TRANSFER_WRITE, sync::COMPUTE_READ);
    p.solve(
        ctx,
        cmd,
        scopes,
        st,
        ("pressure", &["predict", "pressure", "accel"], false),
    )?;
    p.scoped(ctx, cmd, scopes, st, "euler")
}
