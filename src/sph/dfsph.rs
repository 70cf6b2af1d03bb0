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

/// After the arrange, in place of the density and forces passes: densities, factors and
/// the step's neighbour lists, the divergence-free solve, the non-pressure forces (from the
/// lists).
pub fn record_divergence(
    p: &PressurePasses,
    ctx: &Context,
    cmd: vk::CommandBuffer,
    scopes: &mut dyn Scopes,
    st: &SphState,
) -> Result<()> {
    p.scoped(ctx, cmd, scopes, st, "factor")?;
    solve(p, ctx, cmd, scopes, st, "divergence")?;
    p.scoped(ctx, cmd, scopes, st, "forces")
}

/// Warm start, sources, iterations of one solve (`mode`: divergence or density).
fn solve(
    p: &PressurePasses,
    ctx: &Context,
    cmd: vk::CommandBuffer,
    scopes: &mut dyn Scopes,
    st: &SphState,
    mode: &str,
) -> Result<()> {
    let scope = if mode == "density" { "pressure" } else { mode };
    let (velocity, source) = (format!("velocity/{mode}"), format!("source/{mode}"));
    scopes.begin(ctx, cmd, scope);
    let r = p
        .run(ctx, cmd, st, &format!("warm/{mode}"))
        .and_then(|_| p.run(ctx, cmd, st, &source))
        .and_then(|_| {
            p.solve(
                ctx,
                cmd,
                scopes,
                st,
                (
                    "iterations",
                    &[velocity.as_str(), source.as_str()],
                    mode == "divergence",
                ),
            )
        });
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
    solve(p, ctx, cmd, scopes, st, "density")?;
    p.scoped(ctx, cmd, scopes, st, "euler")
}
