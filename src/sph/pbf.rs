//! Position based fluids (Macklin & Mueller 2013): predicted positions from the
//! non-pressure forces, density-constraint iterations (lambda, correction with s_corr,
//! apply) to the density error target or a fixed count, velocities from the positions,
//! then vorticity confinement and XSPH viscosity (glsl/sph/pbf.comp).
use super::pressure::PressurePasses;
use super::solver::SphState;
use crate::error::Result;
use crate::gpu::{Context, Scopes};
use ash::vk;

/// The step after the forces pass (no viscous force: XSPH replaces it) and force hooks.
pub fn record(
    p: &PressurePasses,
    ctx: &Context,
    cmd: vk::CommandBuffer,
    scopes: &mut dyn Scopes,
    st: &SphState,
) -> Result<()> {
    p.scoped(ctx, cmd, scopes, st, "predict")?;
    p.solve(
        ctx,
        cmd,
        scopes,
        st,
        ("pressure", &["lambda", "delta", "apply"], false),
    )?;
    p.scoped(ctx, cmd, scopes, st, "velocity")?;
    if st.fluid.xsph > 0.0 || st.fluid.vorticity > 0.0 {
        scopes.begin(ctx, cmd, "vorticity");
        p.run(ctx, cmd, st, "vorticity")?;
        p.run(ctx, cmd, st, "confine")?;
        scopes.end(ctx, cmd);
    }
    Ok(())
}
