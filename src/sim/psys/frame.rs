//! A frame of particle systems: the frame's constants, and the recording every player
//! shares (`run`, `bench particles`): the steps, the events' children, the depth sorts.
use super::gpu::Passes;
use super::system::{FrameInfo, ParticleSystem};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Context, Scopes};
use crate::render::Camera;

/// Frame `frame` of a scene stepping `dt` per frame, drawn `width` x `height` by `cam`.
pub fn frame_info(cam: &Camera, dt: f32, frame: u64, width: u32, height: u32) -> FrameInfo<'_> {
    FrameInfo {
        cam,
        time: frame as f64 * dt as f64,
        dt,
        frame,
        width,
        height,
        character: None,
    }
}

/// Record the systems' steps, then their depth sorts; their writes made visible to the
/// draws (vertex shaders and indirect arguments). `run` and `bench particles` share it.
pub fn record_simulation(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    prof: &mut dyn Scopes,
    passes: &Passes,
    systems: &mut [ParticleSystem],
    f: &FrameInfo,
) -> Result<()> {
    for s in systems.iter_mut() {
        s.record_step(ctx, cmd, prof, passes, f);
    }
    record_events(ctx, cmd, prof, passes, systems, f)?;
    for s in systems.iter_mut() {
        s.record_sort(ctx, cmd, prof, passes, f)?;
    }
    Ok(())
}

/// Record the children of every event the steps recorded: each parent's spawn dispatch,
/// then the children born into their systems' drawn lists, then those draws' counts.
fn record_events(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    prof: &mut dyn Scopes,
    passes: &Passes,
    systems: &[ParticleSystem],
    f: &FrameInfo,
) -> Result<()> {
    let mut links = Vec::new();
    for (i, s) in systems.iter().enumerate() {
        for e in &s.spec.event {
            let j = systems
                .iter()
                .position(|t| t.spec.name == e.spawn)
                .ok_or_else(|| {
                    Error::Param(format!(
                        "system '{}' spawns '{}', which is not among the scene's systems",
                        s.spec.name, e.spawn
                    ))
                })?;
            links.push((i, j, e));
        }
    }
    if links.is_empty() {
        return Ok(());
    }
    {
        let _scope = prof.open(ctx, cmd, Passes::EVENTS);
        for (i, s) in systems.iter().enumerate() {
            if links.iter().any(|l| l.0 == i) {
                s.record_event_args(ctx, cmd, passes, f);
            }
        }
        for &(i, j, e) in &links {
            systems[j].record_spawn(ctx, cmd, passes, f, &systems[i], e);
        }
        let mut targets: Vec<usize> = links.iter().map(|l| l.1).collect();
        targets.sort_unstable();
        targets.dedup();
        for j in targets {
            systems[j].record_draw_count(ctx, cmd, passes, f);
        }
    }
    Ok(())
}
