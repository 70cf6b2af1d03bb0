//! Each step's dt from its own velocities, on the GPU (glsl/sph/cfl.comp): with `fluid.cfl`
//! set, a step starts with the largest speed of its particles and takes
//! dt = min(dt_max, cfl h / max(v_max, c)) (c: wcsph's speed of sound, else 0), written
//! into the parameters every pass reads, the previous step's dt kept for the warm starts.
//! One dispatch: its last workgroup sets dt (glsl/sph/cfl.glsl). PCISPH's and DFSPH's
//! Euler pass does the same for the next step from the velocities it leaves, so a step
//! that follows in the same recording with its parameters not uploaded again records none.
//! The host records a frame's steps from the last finished frame's dt and how far the
//! simulated time trails the frames (`stepper::Stepper`): no step is snapped to the frame
//! grid, and the time a frame leaves over carries into the next.
use super::params::SphGpuParams;
use super::solver::SphState;
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard};
use bytemuck::{Pod, Zeroable};

const WG: u32 = 256;
const ITEMS: u32 = 8;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CflPush {
    pub n: u32,
    /// Workgroups of the dispatch (the last to arrive sets dt).
    pub parts: u32,
    pub cfl: f32,
    pub dt_max: f32,
    pub speed: f32,
    /// dt_prev's index among the floats after SphGpuParams' h.
    pub dt_prev: u32,
}

crate::gpu_interface! {
    /// glsl/sph/cfl.comp
    pub CflIo / CflBufs: "CFL", push CflPush { params = 0, pos = 1, vel = 2, clock = 3 }
}

/// Bytes of `ClockState` in glsl/sph/cfl.glsl: the largest |v|^2's bits, the next step's
/// dt and its previous step's, whether a step's end set them, the arrivals, padding.
const CLOCK_BYTES: u64 = 32;

/// The bytes of SphGpuParams up to and including `h` (cfl.comp's SphParamsHead).
const HEAD: usize = std::mem::offset_of!(SphGpuParams, h) + 4;
const DT_PREV: u32 = ((std::mem::offset_of!(SphGpuParams, dt_prev) - HEAD) / 4) as u32;

crate::gpu::compute_pass!(pub CFL: CflIo, () = "cfl", "sph/cfl.comp");

pub struct CflPass {
    pipeline: ComputePipeline<CflIo>,
}

impl CflPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: CFL.pipeline(ctx, &(), WG, &[ITEMS])?,
        })
    }

    /// The step's dt into the parameters (after they are uploaded), when the fluid sets a
    /// CFL number; else nothing.
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, st: &SphState) {
        let f = &st.fluid;
        let Some(cfl) = f.cfl else { return };
        let groups = (st.n as u64).div_ceil((WG * ITEMS) as u64).max(1);
        let push = CflPush {
            n: st.n,
            parts: groups as u32,
            cfl,
            dt_max: f.dt_max.unwrap_or(f.dt),
            speed: f.sound(),
            dt_prev: DT_PREV,
        };
        let bufs = CflBufs {
            params: st.params(),
            pos: st.pos(),
            vel: st.vel(),
            clock: &st.clock,
        };
        self.pipeline
            .dispatch_groups(ctx, cmd, &bufs, &push, groups);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}

/// The state's clock buffer, zeroed.
pub fn clock_buffer(ctx: &Context) -> Result<Buffer> {
    let b = Guard::new(ctx, ctx.storage_buffer("sph clock", CLOCK_BYTES)?);
    ctx.one_shot(|cmd| ctx.fill(cmd, &b, 0))?;
    Ok(b.take())
}

crate::impl_destroy!(CflPass);
