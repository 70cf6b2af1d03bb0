//! DFSPH (Bender & Koschier 2015): the divergence-free solve on the step's start velocities
//! (after the neighbourhoods and densities are new; the paper's end-of-step solve, moved to
//! the next step's start), then the non-pressure forces, then the constant-density solve on
//! the predicted velocities, both warm-started with last step's stiffness, then symplectic
//! Euler (glsl/sph/dfsph.comp, euler.comp).
use super::pressure::PressurePasses;
use super::solver::SphState;
use crate::error::Result;
use crate::gpu::{Context, Scopes};
use ash::vk;

/// After the density pass: factors and the divergence-free solve.
pub fn record_divergence(
    p: &PressurePasses,
    ctx: &Context,
    cmd: vk::CommandBuffer,
    scopes: &mut dyn Scopes,
    st: &SphState,
) -> Result<()> {
    p.scoped(ctx, cmd, scopes, st, "factor")?;
    scopes.begin(ctx, cmd, "divergence");
    p.run(ctx, cmd, st, "warm/divergence")?;
    p.run(ctx, cmd, st, "source/divergence")?;
    let r = p.solve(
        ctx,
        cmd,
        scopes,
        st,
        (
            "iterations",
            &["velocity/divergence", "source/divergence"],
            true,
        ),
    );
    scopes.end(ctx, cmd);
    r
}

/// After the forces and the force hooks: predicted velocities, the constant-density solve,
/// the positions.
pub fn record_density(
    p: &PressurePasses,
    ctx: &Context,
    cmd: vk::CommandBuffer,
    scopes: &mut dyn Scopes,
    st: &SphState,
) -> Result<()> {
    p.scoped(ctx, cmd, scopes, st, "predict")?;
    scopes.begin(ctx, cmd, "pressure");
    p.run(ctx, cmd, st, "warm/density")?;
    p.run(ctx, cmd, st, "source/density")?;
    let r = p.solve(
        ctx,
        cmd,
        scopes,
        st,
        ("iterations", &["velocity/density", "source/density"], false),
    );
    scopes.end(ctx, cmd);
    r?;
    p.scoped(ctx, cmd, scopes, st, "euler")
}
