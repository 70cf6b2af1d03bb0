//! Named hooks into the SPH step: extra force terms (between forces and integrate; they add
//! into `acc`) and extra per-particle passes (before arrange). A hook is its own module
//! with its GLSL beside it; whoever owns it (the scene: emitter, control targets) lends it
//! to each step's recording in [`Hooks`], so it keeps its own state with `&mut self`.
use super::solver::SphState;
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context};
use bytemuck::{Pod, Zeroable};

pub trait SphHook {
    /// Timestamp scope and debug label (under `sph/`).
    fn scope(&self) -> crate::gpu::ScopeName;
    /// Record the hook's passes for the state's `n` particles (sub-scopes in `scopes`);
    /// the solver orders them after the previous pass and before the next.
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn crate::gpu::Scopes,
        st: &SphState,
    ) -> Result<()>;
    fn destroy(&mut self, ctx: &Context);
}

/// The hooks lent to one step's recording, each list in its order.
#[derive(Default)]
pub struct Hooks<'a> {
    /// Per-particle passes run at the start of the step, before arrange (emission).
    pub pre_arrange: Vec<&'a mut dyn SphHook>,
    /// Extra force terms, run after the forces pass (they add into `acc`).
    pub force: Vec<&'a mut dyn SphHook>,
}

impl Hooks<'_> {
    /// No hooks: the plain step.
    pub fn none() -> Self {
        Self::default()
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]

pub struct ConstantForcePush {
    /// xyz: acceleration added to every particle, m/s^2.
    pub accel: [f32; 4],
    pub n: u32,
}

crate::gpu_interface! {
    /// glsl/sph/constant_force.comp
    pub ConstantForceIo / ConstantForceBufs: "CF", push ConstantForcePush { acc = 0 }
}

crate::gpu::compute_pass!(pub CONSTANT_FORCE: ConstantForceIo, () = "constant force", "sph/constant_force.comp");

/// A uniform extra acceleration (a steady wind, a tilted gravity): the smallest force
/// term, the reference for how one plugs into the step.
pub struct ConstantForce {
    pipeline: ComputePipeline<ConstantForceIo>,
    pub accel: [f32; 3],
}

impl ConstantForce {
    pub fn new(ctx: &Context, accel: [f32; 3]) -> Result<Self> {
        Ok(Self {
            pipeline: CONSTANT_FORCE.pipeline(ctx, &(), 128, &[])?,
            accel,
        })
    }
}

impl ConstantForce {
    /// Add the acceleration to `acc` over as many groups as the GPU-side count's indirect
    /// arguments say (`args` at `offset`); `bound` is the bounds check (the capacity).
    pub fn record_indirect(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        acc: &Buffer,
        bound: u32,
        args: &Buffer,
        offset: u64,
    ) {
        let push = ConstantForcePush {
            accel: [self.accel[0], self.accel[1], self.accel[2], 0.0],
            n: bound,
        };
        self.pipeline
            .dispatch_indirect(ctx, cmd, &ConstantForceBufs { acc }, &push, args, offset);
    }
}

impl SphHook for ConstantForce {
    fn scope(&self) -> crate::gpu::ScopeName {
        CONSTANT_FORCE.scope()
    }

    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        _: &mut dyn crate::gpu::Scopes,
        st: &SphState,
    ) -> Result<()> {
        let push = ConstantForcePush {
            accel: [self.accel[0], self.accel[1], self.accel[2], 0.0],
            n: st.n,
        };
        let acc: &Buffer = st.acc();
        self.pipeline
            .dispatch(ctx, cmd, &ConstantForceBufs { acc }, &push, st.n as u64);
        Ok(())
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
