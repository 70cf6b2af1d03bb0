//! The GPU SPH step: pre-arrange hooks, arrange (neighbour keys, sort, cell ranges, every
//! reordered attribute into sorted order), density, forces, extra force terms, integrate.
//! Every pass a compute shader. Particle state is a registry (particles.rs): a hook adds
//! its own attribute with one `register` call; its pass is an `SphHook` lent to each step
//! (hooks.rs).
use super::hooks::{Hooks, SphHook};
use super::params::{FluidParams, GpuCollider, LatticeTerms, SphGpuParams, MAX_COLLIDERS};
use super::pressure::{PressureBuffers, PressureSolver};
use super::setup::{Particles, SphSetup};
use crate::error::{Error, Result};
use crate::gpu::pass::{Defines, PassKey};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard, Scopes};
use crate::kinds::{Neighbors, SortAlgo};
use crate::primitives::counting::GatherPass;
use crate::primitives::neighbors::{
    GridSpec, NbKey, NeighborBuffers, NeighborPush, NeighborSearch,
};
use crate::sph::store::{AttrId, AttributeDecl, ParticleStore};
use crate::sph::Solver;

const ARRANGE_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("arrange");

crate::gpu_interface! {
    /// glsl/sph/common.glsl: every SPH pass declares all of these.
    pub SphIo / SphBufs: "SPH", push NeighborPush {
        params = 0, nb_keys = 1, nb_start = 2, nb_end = 3, nb_box = 4,
        pos = 5, vel = 6, rho_p = 7, acc = 8, vhalf = 9, colliders = 10,
    }
}

/// The solver's attributes, registered in this order.
pub const POS: AttrId = AttrId(0);
pub const VEL: AttrId = AttrId(1);
pub const VHALF: AttrId = AttrId(2);
/// Group and colour.
pub const ATTR: AttrId = AttrId(3);
/// (density, pressure), recomputed every step.
pub const RHO_P: AttrId = AttrId(4);
/// Acceleration, recomputed every step.
pub const ACC: AttrId = AttrId(5);
const ATTRIBUTES: [AttributeDecl; 6] = [
    AttributeDecl {
        name: "positions",
        bytes: 16,
        reorder: true,
    },
    AttributeDecl {
        name: "velocities",
        bytes: 16,
        reorder: true,
    },
    AttributeDecl {
        name: "half-step velocities",
        bytes: 16,
        reorder: true,
    },
    AttributeDecl {
        name: "attributes",
        bytes: 16,
        reorder: true,
    },
    AttributeDecl {
        name: "density pressure",
        bytes: 8,
        reorder: false,
    },
    AttributeDecl {
        name: "accelerations",
        bytes: 16,
        reorder: false,
    },
];

/// Most particles a scene may have.
pub const MAX_PARTICLES: u64 = 1 << 26;

/// Device bytes per particle, an upper bound for the solver's state and neighbour buffers
/// (the pressure solvers' included) and a view's per-particle buffers (measured in
/// tests/sph), for refusing scenes that cannot fit before anything is made.
pub const BYTES_PER_PARTICLE: u64 = 320 + super::pressure::BYTES_PER_PARTICLE;

/// [`BYTES_PER_PARTICLE`] with the fluid's neighbour lists.
pub fn bytes_per_particle(f: &super::FluidParams) -> u64 {
    BYTES_PER_PARTICLE + super::pressure::list_bytes(f.list_len())
}

/// Local size of the per-particle passes.
pub const LOCAL_SIZE: u32 = 128;

pub struct SphSolver {
    pub search: NeighborSearch,
    gather: GatherPass,
    density: ComputePipeline<SphIo>,
    forces: ComputePipeline<SphIo>,
    integrate: ComputePipeline<SphIo>,
    /// The step's dt from its velocities (with `fluid.cfl`).
    cfl: super::cfl::CflPass,
    /// The pressure solvers built so far (`state` builds its fluid's).
    pressure: Vec<Box<dyn PressureSolver>>,
}

/// Particle state and scratch for up to `particles.capacity` particles.
pub struct SphState {
    pub particles: ParticleStore,
    params: Buffer,
    colliders: Buffer,
    pub nb: NeighborBuffers,
    pub n: u32,
    pub grid: GridSpec,
    pub fluid: FluidParams,
    pub domain: ([f32; 3], [f32; 3]),
    collider_list: Vec<GpuCollider>,
    /// Current step size (the CFL limit may lower it below fluid.dt; with `fluid.cfl` the
    /// GPU's is the step's own and this the host's estimate of it).
    pub dt: f32,
    /// The GPU's clock (sph/cfl.rs): the last step's dt and the simulated time.
    pub clock: Buffer,
    /// The incompressible solvers' buffers (None for wcsph).
    pub pressure: Option<PressureBuffers>,
    /// Iterations the next steps record per solve (density, divergence); 0: max_iter.
    /// The Stepper lowers it from the counts it reads back (see `Stepper::retire_slot`).
    pub iteration_bound: [u32; 2],
    /// What the last step recorded.
    pub commands: super::commands::StepCommands,
    /// The parameters and colliders last uploaded (their bytes), and the recording
    /// (`Context::recording`) they were uploaded in: a step that would upload the same
    /// in the same recording uploads nothing.
    uploaded: Option<(u64, Vec<u8>)>,
    /// The recording whose last step ended by setting the next step's dt (euler.comp):
    /// a step that follows it there, with its parameters not uploaded again, has its dt.
    next_dt: Option<u64>,
    /// `fluid`'s rest-lattice sums, once (recomputed by `gpu_params` if `fluid` changed).
    lattice: LatticeTerms,
}

impl SphState {
    pub fn pos(&self) -> &Buffer {
        self.particles.get(POS)
    }
    pub fn vel(&self) -> &Buffer {
        self.particles.get(VEL)
    }
    pub fn attr(&self) -> &Buffer {
        self.particles.get(ATTR)
    }
    pub fn acc(&self) -> &Buffer {
        self.particles.get(ACC)
    }
    pub fn rho_p(&self) -> &Buffer {
        self.particles.get(RHO_P)
    }
    /// The parameters buffer (SphParams) of the current step.
    pub fn params(&self) -> &Buffer {
        &self.params
    }

    /// The neighbour query constants of every SPH pass.
    pub fn neighbor_push(&self) -> NeighborPush {
        NeighborSearch::push(&self.nb, &self.grid, self.fluid.h, self.n)
    }

    /// The buffers every SPH pass binds, in the current order.
    pub fn bufs(&self) -> SphBufs<'_> {
        let (nb_start, nb_end) = self.nb.cell_buffers();
        SphBufs {
            params: &self.params,
            nb_keys: &self.nb.sorted_keys,
            nb_start,
            nb_end,
            nb_box: self.nb.box_buffer(),
            pos: self.pos(),
            vel: self.vel(),
            rho_p: self.rho_p(),
            acc: self.acc(),
            vhalf: self.particles.get(VHALF),
            colliders: &self.colliders,
        }
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
        SphGpuParams::with_lattice(
            &self.fluid,
            &self.lattice,
            self.domain,
            self.dt,
            self.collider_list.len() as u32,
        )
    }

    /// Positions, velocities, attributes, (density, pressure) and accelerations of the live
    /// particles (dead slots, pos.w < 0, left out), in the current (sorted) order.
    pub fn read(&self, ctx: &Context) -> Result<StateDump> {
        let n = self.n as usize;
        let p = &self.particles;
        let d = StateDump {
            pos: p.read(ctx, POS, n)?,
            vel: p.read(ctx, VEL, n)?,
            attr: p.read(ctx, ATTR, n)?,
            rho_p: p.read(ctx, RHO_P, n)?,
            acc: p.read(ctx, ACC, n)?,
        };
        Ok(d.live())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.particles.destroy(ctx);
        ctx.destroy_buffer(&mut self.params);
        ctx.destroy_buffer(&mut self.clock);
        ctx.destroy_buffer(&mut self.colliders);
        self.nb.destroy(ctx);
        if let Some(p) = &mut self.pressure {
            p.destroy(ctx);
        }
    }
}

pub struct StateDump {
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    pub attr: Vec<[f32; 4]>,
    pub rho_p: Vec<[f32; 2]>,
    pub acc: Vec<[f32; 4]>,
}

/// Per particle: live (pos.w >= 0; an emitter's dead slots have -1).
pub fn live_mask(pos: &[[f32; 4]]) -> Vec<bool> {
    pos.iter().map(|p| p[3] >= 0.0).collect()
}

/// The elements of `v` whose `keep` is set.
pub fn pick<T: Copy>(v: &[T], keep: &[bool]) -> Vec<T> {
    v.iter()
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|(x, _)| *x)
        .collect()
}

impl StateDump {
    /// Only the live particles (pos.w >= 0).
    pub fn live(self) -> Self {
        if self.pos.iter().all(|p| p[3] >= 0.0) {
            return self;
        }
        let keep = live_mask(&self.pos);
        Self {
            pos: pick(&self.pos, &keep),
            vel: pick(&self.vel, &keep),
            attr: pick(&self.attr, &keep),
            rho_p: pick(&self.rho_p, &keep),
            acc: pick(&self.acc, &keep),
        }
    }
}

/// The SPH passes' variant: the neighbour search they include, with the fluid's and the
/// pressure solvers' constants.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SphKey(pub NbKey);

impl PassKey for SphKey {
    fn all() -> Vec<Self> {
        NbKey::all().into_iter().map(Self).collect()
    }
    fn defines(&self) -> Defines {
        let mut d = self.0.defines();
        d.extend(super::params::defines());
        d.extend(super::pressure::solver_defines());
        d
    }
}

crate::gpu::compute_pass!(pub DENSITY: SphIo, SphKey = "density", "sph/density.comp");
crate::gpu::compute_pass!(pub FORCES: SphIo, SphKey = "forces", "sph/forces.comp");
crate::gpu::compute_pass!(pub INTEGRATE: SphIo, SphKey = "integrate", "sph/integrate.comp");

impl SphSolver {
    pub fn new(ctx: &Context, neighbors: Neighbors, sort: Option<SortAlgo>) -> Result<Self> {
        let search = Guard::new(ctx, NeighborSearch::new(ctx, neighbors, sort)?);
        let key = SphKey(search.key());
        let density = Guard::new(ctx, DENSITY.pipeline(ctx, &key, LOCAL_SIZE, &[])?);
        let forces = Guard::new(ctx, FORCES.pipeline(ctx, &key, LOCAL_SIZE, &[])?);
        let integrate = Guard::new(ctx, INTEGRATE.pipeline(ctx, &key, LOCAL_SIZE, &[])?);
        let cfl = Guard::new(ctx, super::cfl::CflPass::new(ctx)?);
        let gather = GatherPass::new(ctx)?;
        Ok(Self {
            density: density.take(),
            forces: forces.take(),
            integrate: integrate.take(),
            cfl: cfl.take(),
            gather,
            search: search.take(),
            pressure: Vec::new(),
        })
    }

    /// Build the passes of `solver` (once).
    pub fn prepare(&mut self, ctx: &Context, solver: Solver) -> Result<&dyn PressureSolver> {
        let k = match self.pressure.iter().position(|p| p.kind() == solver) {
            Some(k) => k,
            None => {
                self.pressure.push(super::pressure::build(
                    ctx,
                    solver,
                    &SphKey(self.search.key()),
                )?);
                self.pressure.len() - 1
            }
        };
        Ok(self.pressure[k].as_ref())
    }

    /// Buffers for `particles` in the fluid `setup` (a scene gives one), uploaded; the
    /// passes of its solver built.
    pub fn state<'a>(
        &mut self,
        ctx: &Context,
        setup: impl Into<SphSetup<'a>>,
        particles: &Particles,
    ) -> Result<SphState> {
        let scene: SphSetup = setup.into();
        scene.validate()?;
        let n = particles.len();
        if n == 0 {
            return Err(Error::Param(format!(
                "scene {} has no particle inside its domain",
                scene.name
            )));
        }
        if n as u64 > MAX_PARTICLES {
            return Err(Error::Param(format!("{n} particles: at most 2^26")));
        }
        // The kernel's support applied here too: a FluidParams made without
        // with_overrides (a test's, a library user's) gets the same h.
        let f = &scene.fluid.resolved()?;
        let grid = GridSpec::covering(scene.domain.min, scene.domain.max, f.h)?;
        let colliders: Vec<GpuCollider> = scene
            .colliders
            .iter()
            .map(|c| c.to_gpu())
            .collect::<Result<_>>()?;
        let mut store = Guard::new(ctx, ParticleStore::new(ctx, "sph", n as u64)?);
        for d in ATTRIBUTES {
            store.register(ctx, d)?;
        }
        store.set_live(ctx, n as u32, LOCAL_SIZE)?;
        store.upload(ctx, POS, &particles.pos)?;
        store.upload(ctx, VEL, &particles.vel)?;
        store.upload(ctx, VHALF, &particles.vel)?;
        store.upload(ctx, ATTR, &particles.attr)?;
        // Dead slots (an emitter's) are never written by the step: start them finite.
        store.upload(ctx, RHO_P, &vec![[0.0f32; 2]; n])?;
        store.upload(ctx, ACC, &vec![[0.0f32; 4]; n])?;
        let params = Guard::new(
            ctx,
            ctx.storage_buffer("sph params", std::mem::size_of::<SphGpuParams>() as u64)?,
        );
        let colliders_buf = Guard::new(
            ctx,
            ctx.storage_buffer(
                "sph colliders",
                (MAX_COLLIDERS * std::mem::size_of::<GpuCollider>()) as u64,
            )?,
        );
        let pressure = match self.prepare(ctx, f.solver)?.buffers() {
            false => None,
            true => Some(PressureBuffers::new(ctx, n as u64, f.list_len())?),
        };
        let pressure = Guard::new(ctx, pressure);
        let clock = Guard::new(ctx, super::cfl::clock_buffer(ctx)?);
        let nb = self.search.buffers(ctx, n as u64, &grid, 0)?;
        Ok(SphState {
            particles: store.take(),
            params: params.take(),
            colliders: colliders_buf.take(),
            nb,
            n: n as u32,
            grid,
            fluid: f.clone(),
            domain: (scene.domain.min, scene.domain.max),
            collider_list: colliders,
            dt: f.dt,
            clock: clock.take(),
            pressure: pressure.take(),
            iteration_bound: [0; 2],
            commands: Default::default(),
            uploaded: None,
            next_dt: None,
            lattice: LatticeTerms::of(f),
        })
    }

    /// Upload parameters and colliders for the next step (inside the command buffer).
    pub fn record_params(&self, ctx: &Context, cmd: vk::CommandBuffer, st: &SphState) {
        let p = st.gpu_params();
        ctx.update(cmd, &st.params, 0, &[p]);
        ctx.update(cmd, &st.colliders, 0, &st.collider_list);
    }

    /// [`record_params`](Self::record_params) unless this recording has uploaded the same
    /// already: the steps of a frame share their parameters (dt is the frame's estimate).
    /// Whether it uploaded.
    fn record_changed_params(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        st: &mut SphState,
    ) -> bool {
        let mut bytes = bytemuck::bytes_of(&st.gpu_params()).to_vec();
        bytes.extend_from_slice(bytemuck::cast_slice(&st.collider_list));
        let now = (ctx.recording(cmd), bytes);
        if st.uploaded.as_ref() == Some(&now) {
            return false;
        }
        self.record_params(ctx, cmd, st);
        st.uploaded = Some(now);
        true
    }

    /// Neighbour structure and every reordered attribute in sorted order.
    pub fn record_arrange(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &mut SphState,
    ) -> Result<()> {
        {
            let mut scopes = scopes.open(ctx, cmd, ARRANGE_SCOPE);
            self.search
                .record_build(ctx, cmd, &mut *scopes, &st.nb, st.pos(), st.n, &st.grid)?;
            st.particles
                .record_reorder(ctx, cmd, &mut *scopes, &self.gather, &st.nb.perm);
        }
        Ok(())
    }

    pub fn record_density(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) {
        self.run(ctx, cmd, scopes, st, &self.density, DENSITY.scope());
    }

    pub fn record_forces(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) {
        self.run(ctx, cmd, scopes, st, &self.forces, FORCES.scope());
    }

    pub fn record_integrate(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) {
        self.run(ctx, cmd, scopes, st, &self.integrate, INTEGRATE.scope());
    }

    fn run(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
        p: &ComputePipeline<SphIo>,
        name: crate::gpu::ScopeName,
    ) {
        let _scope = scopes.open(ctx, cmd, name);
        p.dispatch(ctx, cmd, &st.bufs(), &st.neighbor_push(), st.n as u64);
    }

    fn run_hooks(
        hooks: &mut [&mut dyn SphHook],
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        for h in hooks {
            let mut scopes = scopes.open(ctx, cmd, h.scope());
            h.record(ctx, cmd, &mut *scopes, st)?;
        }
        Ok(())
    }

    /// One full step without hooks, in the scope `sph`.
    pub fn record_step(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &mut SphState,
    ) -> Result<()> {
        self.record_hooked_step(ctx, cmd, scopes, st, &mut Hooks::none())
    }

    /// One full step with the `hooks` lent to it, in the scope `sph`.
    pub fn record_hooked_step(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &mut SphState,
        hooks: &mut Hooks,
    ) -> Result<()> {
        let solver = st.fluid.solver;
        let p = self.pressure.iter().find(|p| p.kind() == solver).ok_or_else(|| {
            Error::Param(format!(
                "the {} passes were not built: make the state with SphSolver::state, or call prepare",
                solver.as_str()
            ))
        })?;
        if p.buffers() {
            st.pressure()?; // a state made for another solver: a clear error, nothing recorded
        }
        let start = ctx.recorded(cmd);
        let (forces, hooked, solve, end) = {
            let mut scopes = scopes.open(ctx, cmd, super::SCOPE.scope());
            let uploaded = self.record_changed_params(ctx, cmd, st);
            let recording = ctx.recording(cmd);
            if uploaded || st.next_dt != Some(recording) {
                let _scope = scopes.open(ctx, cmd, super::cfl::CFL.scope());
                self.cfl.record(ctx, cmd, st);
            }
            st.next_dt = None;
            Self::run_hooks(&mut hooks.pre_arrange, ctx, cmd, &mut *scopes, st)?;
            self.record_arrange(ctx, cmd, &mut *scopes, st)?;
            let forces = ctx.recorded(cmd);
            p.record_forces(self, ctx, cmd, &mut *scopes, st)?;
            let hooked = ctx.recorded(cmd);
            Self::run_hooks(&mut hooks.force, ctx, cmd, &mut *scopes, st)?;
            let solve = ctx.recorded(cmd);
            p.record_solve(self, ctx, cmd, &mut *scopes, st)?;
            if p.sets_next_dt() && st.fluid.cfl.is_some() {
                st.next_dt = Some(recording);
            }
            (forces, hooked, solve, ctx.recorded(cmd))
        };
        let solves = p.solves();
        let iterations = [false, true].map(|d| match solves[d as usize] {
            true => st.recorded_iterations(d),
            false => 0,
        });
        st.commands = super::commands::StepCommands {
            step: end - start,
            solver: (hooked - forces) + (end - solve),
            iterations,
            per_iteration: p.iteration_dispatches(),
        };
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.search.destroy(ctx);
        self.gather.destroy(ctx);
        self.density.destroy(ctx);
        self.forces.destroy(ctx);
        self.integrate.destroy(ctx);
        self.cfl.destroy(ctx);
        for p in &mut self.pressure {
            p.destroy(ctx);
        }
    }
}

crate::impl_destroy!(SphSolver, SphState);
