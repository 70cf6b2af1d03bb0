//! The GPU SPH step: arrange (neighbour keys, sort, cell ranges, reorder every particle
//! attribute into sorted order), density, forces, integrate. Every pass a compute shader.
//! Extra force terms (control particles) add into `acc` between forces and integrate.
use super::params::{FluidParams, GpuCollider, SphGpuParams, MAX_COLLIDERS};
use super::scene::{Particles, Scene};
use crate::config::{Neighbors, SortAlgo};
use crate::error::{Error, Result};
use crate::gpu::{Buffer, ComputeDesc, ComputePipeline, Context, Scopes};
use crate::primitives::counting::GatherPass;
use crate::primitives::neighbors::{GridSpec, NeighborBuffers, NeighborPush, NeighborSearch};
use ash::vk;

/// Bindings of the SPH passes (glsl/sph/common.glsl).
const BINDINGS: u32 = 11;

pub struct SphSolver {
    pub search: NeighborSearch,
    gather: GatherPass,
    density: ComputePipeline,
    forces: ComputePipeline,
    integrate: ComputePipeline,
}

/// Particle state (double-buffered for the reorder) and scratch for up to `capacity`.
pub struct SphState {
    pos: [Buffer; 2],
    vel: [Buffer; 2],
    vhalf: [Buffer; 2],
    attr: [Buffer; 2],
    cur: usize,
    pub rho_p: Buffer,
    pub acc: Buffer,
    params: Buffer,
    colliders: Buffer,
    pub nb: NeighborBuffers,
    pub n: u32,
    pub grid: GridSpec,
    pub fluid: FluidParams,
    pub domain: ([f32; 3], [f32; 3]),
    collider_list: Vec<GpuCollider>,
    /// Current step size (the CFL limit may lower it below fluid.dt).
    pub dt: f32,
}

impl SphState {
    pub fn pos(&self) -> &Buffer {
        &self.pos[self.cur]
    }
    pub fn vel(&self) -> &Buffer {
        &self.vel[self.cur]
    }
    pub fn attr(&self) -> &Buffer {
        &self.attr[self.cur]
    }

    /// Replace the colliders (moving colliders: call before each step with new positions
    /// and velocities; recorded into the command buffer, so safe with frames in flight).
    pub fn set_colliders(&mut self, list: &[GpuCollider]) -> Result<()> {
        if list.len() > MAX_COLLIDERS {
            return Err(Error::Param(format!(
                "{} colliders, at most {MAX_COLLIDERS}",
                list.len()
            )));
        }
        self.collider_list = list.to_vec();
        Ok(())
    }

    pub fn gpu_params(&self) -> SphGpuParams {
        SphGpuParams::new(
            &self.fluid,
            self.domain.0,
            self.domain.1,
            self.dt,
            self.collider_list.len() as u32,
        )
    }

    /// Positions, velocities, attributes, (density, pressure) and accelerations, all in the
    /// current (sorted) order.
    pub fn read(&self, ctx: &Context) -> Result<StateDump> {
        let n = self.n as usize;
        Ok(StateDump {
            pos: ctx.readback(self.pos(), 0, n)?,
            vel: ctx.readback(self.vel(), 0, n)?,
            attr: ctx.readback(self.attr(), 0, n)?,
            rho_p: ctx.readback(&self.rho_p, 0, n)?,
            acc: ctx.readback(&self.acc, 0, n)?,
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for pair in [
            &mut self.pos,
            &mut self.vel,
            &mut self.vhalf,
            &mut self.attr,
        ] {
            for b in pair.iter_mut() {
                ctx.destroy_buffer(b);
            }
        }
        for b in [
            &mut self.rho_p,
            &mut self.acc,
            &mut self.params,
            &mut self.colliders,
        ] {
            ctx.destroy_buffer(b);
        }
        self.nb.destroy(ctx);
    }
}

pub struct StateDump {
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    pub attr: Vec<[f32; 4]>,
    pub rho_p: Vec<[f32; 2]>,
    pub acc: Vec<[f32; 4]>,
}

impl SphSolver {
    pub fn new(ctx: &Context, neighbors: Neighbors, sort: Option<SortAlgo>) -> Result<Self> {
        let search = NeighborSearch::new(ctx, neighbors, sort)?;
        let defines = search.defines();
        let push_size = std::mem::size_of::<NeighborPush>() as u32;
        let pipeline = |name, shader| {
            ComputePipeline::new(
                ctx,
                &ComputeDesc::plain(name, shader, &defines, 128, BINDINGS, push_size),
            )
        };
        Ok(Self {
            density: pipeline("density", "sph/density.comp")?,
            forces: pipeline("forces", "sph/forces.comp")?,
            integrate: pipeline("integrate", "sph/integrate.comp")?,
            gather: GatherPass::new(ctx)?,
            search,
        })
    }

    /// Buffers for the scene's particles, uploaded.
    pub fn state(&self, ctx: &Context, scene: &Scene, particles: &Particles) -> Result<SphState> {
        scene.validate()?;
        let n = particles.len();
        if n == 0 {
            return Err(Error::Param(format!(
                "scene {} has no particle inside its domain",
                scene.name
            )));
        }
        if n > 1 << 26 {
            return Err(Error::Param(format!("{n} particles: at most 2^26")));
        }
        let f = &scene.fluid;
        let grid = GridSpec::covering(scene.domain.min, scene.domain.max, f.h)?;
        let vec4s = (n * 16) as u64;
        let pair = |name: &str| -> Result<[Buffer; 2]> {
            Ok([
                ctx.storage_buffer(&format!("{name} A"), vec4s)?,
                ctx.storage_buffer(&format!("{name} B"), vec4s)?,
            ])
        };
        let colliders: Vec<GpuCollider> = scene
            .colliders
            .iter()
            .map(|c| c.to_gpu())
            .collect::<Result<_>>()?;
        let mut st = SphState {
            pos: pair("sph positions")?,
            vel: pair("sph velocities")?,
            vhalf: pair("sph half-step velocities")?,
            attr: pair("sph attributes")?,
            cur: 0,
            rho_p: ctx.storage_buffer("sph density pressure", (n * 8) as u64)?,
            acc: ctx.storage_buffer("sph accelerations", vec4s)?,
            params: ctx.storage_buffer("sph params", std::mem::size_of::<SphGpuParams>() as u64)?,
            colliders: ctx.storage_buffer("sph colliders", (MAX_COLLIDERS * 48) as u64)?,
            nb: self.search.buffers(ctx, n as u64, &grid, 0)?,
            n: n as u32,
            grid,
            fluid: f.clone(),
            domain: (scene.domain.min, scene.domain.max),
            collider_list: colliders,
            dt: f.dt,
        };
        ctx.upload(&mut st.pos[0], 0, &particles.pos)?;
        ctx.upload(&mut st.vel[0], 0, &particles.vel)?;
        ctx.upload(&mut st.vhalf[0], 0, &particles.vel)?;
        ctx.upload(&mut st.attr[0], 0, &particles.attr)?;
        Ok(st)
    }

    fn push(&self, st: &SphState) -> NeighborPush {
        self.search.push(&st.nb, &st.grid, st.fluid.h, st.n)
    }

    fn infos(&self, st: &SphState) -> Vec<vk::DescriptorBufferInfo> {
        let (starts, ends) = st.nb.cell_buffers();
        let c = st.cur;
        [
            &st.params,
            &st.nb.sorted_keys,
            starts,
            ends,
            st.nb.box_buffer(),
            &st.pos[c],
            &st.vel[c],
            &st.rho_p,
            &st.acc,
            &st.vhalf[c],
            &st.colliders,
        ]
        .iter()
        .map(|b| b.info())
        .collect()
    }

    /// Upload parameters and colliders for the next step (inside the command buffer).
    pub fn record_params(&self, ctx: &Context, cmd: vk::CommandBuffer, st: &SphState) {
        let p = st.gpu_params();
        ctx.barrier(cmd); // earlier steps (in submission order) may still read them
        unsafe {
            ctx.device
                .cmd_update_buffer(cmd, st.params.raw, 0, bytemuck::bytes_of(&p));
            if !st.collider_list.is_empty() {
                ctx.device.cmd_update_buffer(
                    cmd,
                    st.colliders.raw,
                    0,
                    bytemuck::cast_slice(&st.collider_list),
                );
            }
        }
        ctx.barrier(cmd);
    }

    /// Neighbour structure and every attribute reordered into sorted order.
    pub fn record_arrange(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &mut SphState,
    ) -> Result<()> {
        scopes.begin(ctx, cmd, "arrange");
        let (a, b) = (st.cur, 1 - st.cur);
        self.search
            .record_build(ctx, cmd, scopes, &st.nb, &st.pos[a], st.n, &st.grid)?;
        ctx.compute_barrier(cmd);
        scopes.begin(ctx, cmd, "reorder");
        for pair in [&st.pos, &st.vel, &st.vhalf, &st.attr] {
            self.gather
                .record(ctx, cmd, &st.nb.perm, &pair[a], &pair[b], st.n);
        }
        scopes.end(ctx, cmd);
        st.cur = b;
        scopes.end(ctx, cmd);
        ctx.barrier(cmd);
        Ok(())
    }

    pub fn record_density(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) {
        self.run(ctx, cmd, scopes, st, &self.density, "density");
    }

    pub fn record_forces(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) {
        self.run(ctx, cmd, scopes, st, &self.forces, "forces");
    }

    pub fn record_integrate(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) {
        self.run(ctx, cmd, scopes, st, &self.integrate, "integrate");
    }

    fn run(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
        p: &ComputePipeline,
        name: &str,
    ) {
        scopes.begin(ctx, cmd, name);
        let groups = (st.n as u64).div_ceil(p.local_size as u64);
        p.dispatch_groups(ctx, cmd, &self.infos(st), &self.push(st), groups);
        scopes.end(ctx, cmd);
        ctx.compute_barrier(cmd);
    }

    /// One full step.
    pub fn record_step(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &mut SphState,
    ) -> Result<()> {
        self.record_params(ctx, cmd, st);
        self.record_arrange(ctx, cmd, scopes, st)?;
        self.record_density(ctx, cmd, scopes, st);
        self.record_forces(ctx, cmd, scopes, st);
        self.record_integrate(ctx, cmd, scopes, st);
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.search.destroy(ctx);
        self.gather.destroy(ctx);
        self.density.destroy(ctx);
        self.forces.destroy(ctx);
        self.integrate.destroy(ctx);
    }
}
