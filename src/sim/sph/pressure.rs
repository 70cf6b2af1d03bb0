//! The incompressible solvers' shared machinery (pcisph.rs, dfsph.rs, pbf.rs): their extra
//! per-particle buffers, their passes (one table, also read by the every-shader-compiles
//! registry), and the iteration loop. A solve records the iterations its state's bound
//! allows (the Stepper's, from the counts it reads back); the pass that reduces an
//! iteration's error decides in its last workgroup to finish whether the solve goes on and,
//! once it has converged, zeroes the group count of the indirect dispatches that remain:
//! no read-back per iteration and no pass of its own, and an iteration past convergence
//! costs its passes' empty dispatches (see `Stepper::retire_slot` for how few are recorded).
use super::solver::SphKey;
use super::solver::{SphSolver, SphState, LOCAL_SIZE};
use crate::error::{Error, Result};
use crate::gpu::pass::{complete, Defines, PassKey};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, ComputeDesc, ComputePipeline, Context, Guard, ScopeName, Scopes};
use crate::primitives::neighbors::NeighborPush;
use crate::sph::Solver;
use bytemuck::{Pod, Zeroable};

crate::gpu_interface! {
    /// glsl/sph/pressure.glsl: SphIo's bindings (same numbers), then the pressure solvers'.
    pub PressureIo / PressureBufs: "SPH", push NeighborPush {
        params = 0, nb_keys = 1, nb_start = 2, nb_end = 3, nb_box = 4,
        pos = 5, vel = 6, rho_p = 7, acc = 8, vhalf = 9, colliders = 10,
        aux = 11, aux2 = 12, partials = 13, solve = 14, nb_list = 15, overflow = 16,
        clock = 17, params_out = 18,
    }
}

/// Mirror of `SolveState` in glsl/sph/pressure.glsl (the pass before a solve starts it).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SolveState {
    /// The iteration passes' VkDispatchIndirectCommand; `gz` is 0 once converged.
    pub gx: u32,
    pub gy: u32,
    pub gz: u32,
    pub iter: u32,
    pub done: u32,
    /// Workgroups of the checking pass that have written their partial error.
    pub arrived: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub density_iters: u32,
    pub divergence_iters: u32,
    /// The solves' own error estimates at their last iteration.
    pub density_err: f32,
    pub divergence_err: f32,
}
const _: () = assert!(std::mem::size_of::<SolveState>() == 48);

/// Bytes per particle the pressure solvers add (aux, aux2), besides the neighbour list.
pub const BYTES_PER_PARTICLE: u64 = 32;

/// Bytes per particle of a neighbour list of `len` entries (and its count).
pub fn list_bytes(len: u32) -> u64 {
    match len {
        0 => 0,
        k => 4 * (k as u64 + 1),
    }
}

/// A solver pass: its name (pipeline label; the timestamp scope of a pass run on its own),
/// its shader, and the variant it is built as.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassDecl {
    pub name: &'static str,
    pub shader: &'static str,
    /// The shader's `PASS`.
    pub pass: PassCode,
    /// DFSPH's divergence solve (its targets and iteration counts).
    pub divergence: bool,
    /// The pass before a solve's iterations: it starts the solve's state.
    pub starts: bool,
    /// The pass that reduces an iteration's error also ends the iteration.
    pub check: bool,
    /// DFSPH: the density solve's first passes, which read the predicted velocities.
    pub predicted: bool,
}

impl PassDecl {
    pub const fn new(name: &'static str, shader: &'static str, pass: PassCode) -> Self {
        Self {
            name,
            shader,
            pass,
            divergence: false,
            starts: false,
            check: false,
            predicted: false,
        }
    }
    pub const fn divergence(self) -> Self {
        Self {
            divergence: true,
            ..self
        }
    }
    pub const fn starts(self) -> Self {
        Self {
            starts: true,
            ..self
        }
    }
    pub const fn check(self) -> Self {
        Self {
            check: true,
            ..self
        }
    }
    pub const fn predicted(self) -> Self {
        Self {
            predicted: true,
            ..self
        }
    }
}

pub const EULER: PassDecl = PassDecl::new("euler", "sph/euler.comp", PassCode::Euler);

crate::gpu::switch_enum!(
    /// The pressure shaders' `PASS` values (glsl/sph/pcisph.comp, dfsph.comp, pbf.comp,
    /// euler.comp and forces.comp; each shader's switch ends in `#error`).
    PassCode {
        Predict,
        Pressure,
        Accel,
        Factor,
        Warm,
        Source,
        Velocity,
        Lambda,
        Delta,
        Apply,
        Vorticity,
        Confine,
        Euler,
        Forces
    }
);

/// A solver's passes as one declaration: `enum Pass { Name = PassDecl, ... }` gives the
/// enum that indexes its pipelines and its table (`Pass::TABLE`) in one order, and
/// registers every pass with every SPH variant for the shader test.
macro_rules! solver_passes {
    ($solver:literal, $(#[$m:meta])* enum $name:ident { $($v:ident = $decl:expr),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub(crate) enum $name { $($v),+ }
        impl $name {
            /// The passes, in the enum's order (its values index the pipelines).
            pub const TABLE: &'static [$crate::sph::pressure::PassDecl] = &[$($decl),+];
        }
        $crate::gpu::inventory::submit! {
            $crate::gpu::pass::Registered {
                name: $solver,
                variants: || $crate::sph::pressure::table_variants($name::TABLE),
            }
        }
    };
}
pub(crate) use solver_passes;

/// A solver's constructor.
type Make = fn(&Context, &SphKey) -> Result<Box<dyn PressureSolver>>;

/// Each solver's pass table and constructor: its one registration line.
fn registered(kind: Solver) -> (&'static [PassDecl], Make) {
    use super::{dfsph::Dfsph, pbf::Pbf, pcisph::Pcisph, wcsph::Wcsph};
    match kind {
        Solver::Wcsph => (&[], |_, _| Ok(Box::new(Wcsph))),
        Solver::Pcisph => (super::pcisph::Pass::TABLE, |c, k| {
            Ok(Box::new(Pcisph::new(c, k)?))
        }),
        Solver::Dfsph => (super::dfsph::Pass::TABLE, |c, k| {
            Ok(Box::new(Dfsph::new(c, k)?))
        }),
        Solver::Pbf => (super::pbf::Pass::TABLE, |c, k| {
            Ok(Box::new(Pbf::new(c, k)?))
        }),
    }
}

/// Build `kind`'s passes for the SPH variant `key`.
pub fn build(ctx: &Context, kind: Solver, key: &SphKey) -> Result<Box<dyn PressureSolver>> {
    (registered(kind).1)(ctx, key)
}

/// Every (file, complete define set) of a solver's table: each pass with every SPH variant.
pub fn table_variants(table: &[PassDecl]) -> Vec<(&'static str, Defines)> {
    let mut v = Vec::new();
    for key in SphKey::all() {
        for d in table {
            let mut own = key.defines();
            own.extend(pass_defines(d));
            v.push((d.shader, complete::<PressureIo>(own)));
        }
    }
    v
}

/// A pressure solver: what a step records after the arrange. The base passes (density,
/// forces, integrate) are `SphSolver`'s; a solver adds its own around them.
pub trait PressureSolver {
    fn kind(&self) -> Solver;

    /// Dispatches one recorded iteration of its solves takes (0: no iterative solve).
    fn iteration_dispatches(&self) -> u32 {
        0
    }

    /// The iterative solves a step records, (density, divergence): those its pass table
    /// checks.
    fn solves(&self) -> [bool; 2] {
        let passes = registered(self.kind()).0;
        [false, true].map(|div| passes.iter().any(|d| d.check && d.divergence == div))
    }

    /// Whether its step ends with euler.comp (its pass table holds it), which takes the
    /// next step's dt when the fluid sets a CFL number (so the next step in the same
    /// recording records no cfl pass).
    fn sets_next_dt(&self) -> bool {
        registered(self.kind()).0.contains(&EULER)
    }

    /// Whether its states need [`PressureBuffers`].
    fn buffers(&self) -> bool {
        true
    }

    /// After the arrange, before the force hooks: densities, and the non-pressure forces
    /// into `acc`.
    fn record_forces(
        &self,
        base: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        base.record_density(ctx, cmd, scopes, st);
        base.record_forces(ctx, cmd, scopes, st);
        Ok(())
    }

    /// After the force hooks: the pressure solve, new velocities and positions.
    fn record_solve(
        &self,
        base: &SphSolver,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()>;

    fn destroy(&mut self, ctx: &Context);
}

/// The defines of one pass, on top of the neighbour search's and the EOS's.
pub fn pass_defines(d: &PassDecl) -> Vec<(String, String)> {
    let mut v = d.pass.define("PASS");
    for (name, on) in [
        ("DIVERGENCE", d.divergence),
        ("START_SOLVE", d.starts),
        ("CHECK", d.check),
        ("PREDICTED", d.predicted),
    ] {
        v.push((name.into(), (on as u32).to_string()));
    }
    v.push(("PARTICLE_WG".into(), format!("{LOCAL_SIZE}u")));
    v.extend(solver_defines());
    v
}

/// `SOLVER_WCSPH`, ... for glsl/sph/common.glsl, one per `kinds::Solver` value.
pub fn solver_defines() -> Vec<(String, String)> {
    Solver::defines("SOLVER")
}

/// A solver's pipelines, built in the order of its pass table; the solver's pass enum
/// (declared with the table, in its order) indexes them: typed handles, no name lookup.
pub struct Pipelines {
    table: &'static [PassDecl],
    list: Vec<ComputePipeline<PressureIo>>,
}

impl Pipelines {
    /// `key`: the SPH variant (neighbour search, the EOS's constants).
    pub fn new(
        ctx: &Context,
        solver: Solver,
        table: &'static [PassDecl],
        key: &SphKey,
    ) -> Result<Self> {
        let mut out = Guard::new(
            ctx,
            Self {
                table,
                list: Vec::new(),
            },
        );
        for d in table {
            let mut own = key.defines();
            own.extend(pass_defines(d));
            let defines = crate::gpu::pipeline::as_refs(&own);
            let label = format!("{}/{}", solver.as_str(), d.name);
            let desc = ComputeDesc::plain(&label, d.shader, &defines, LOCAL_SIZE);
            let p = ComputePipeline::new(ctx, &desc)?;
            out.list.push(p);
        }
        Ok(out.take())
    }

    /// Pass `k` of the table: its name (the timestamp scope) and pipeline.
    fn pass(&self, k: usize) -> (&'static str, &ComputePipeline<PressureIo>) {
        (self.table[k].name, &self.list[k])
    }

    /// Pass `k` over every particle, then its writes -> the next pass.
    pub fn run(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        st: &SphState,
        k: usize,
    ) -> Result<()> {
        let b = st.pressure_bufs()?;
        self.pass(k)
            .1
            .dispatch(ctx, cmd, &b, &st.neighbor_push(), st.n as u64);
        Ok(())
    }

    /// [`run`](Self::run) inside a timestamp scope named after the pass.
    pub fn scoped(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
        k: usize,
    ) -> Result<()> {
        let _scope = scopes.open(ctx, cmd, ScopeName::new(self.pass(k).0));
        self.run(ctx, cmd, st, k)
    }

    /// An iterative solve in the scope `scope`, its state started by the pass before it:
    /// `checked` are an iteration's passes up to the one that checks (last), `rest` the
    /// ones after it. Recorded as `checked`, then (`rest`, `checked`) for each further
    /// iteration, then `rest` once, directly: the iteration that stops still finishes.
    /// `divergence`: the divergence solve (its own iteration bound).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
        scope: ScopeName,
        (checked, rest): (&[usize], &[usize]),
        divergence: bool,
    ) -> Result<()> {
        let b = st.pressure_bufs()?;
        let solve = st.pressure()?.solve();
        let push = st.neighbor_push();
        {
            let _scope = scopes.open(ctx, cmd, scope);
            let checked: Vec<_> = checked.iter().map(|k| self.pass(*k).1).collect();
            let rest: Vec<_> = rest.iter().map(|k| self.pass(*k).1).collect();
            for k in 0..st.recorded_iterations(divergence) {
                let passes = if k == 0 { &rest[..0] } else { &rest[..] };
                for p in passes.iter().chain(&checked) {
                    p.dispatch_indirect(ctx, cmd, &b, &push, solve, 0);
                }
            }
            for p in &rest {
                p.dispatch(ctx, cmd, &b, &push, st.n as u64);
            }
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for p in &mut self.list {
            p.destroy(ctx);
        }
    }
}

/// The pressure solvers' buffers, beside the state's.
pub struct PressureBuffers {
    aux: Buffer,
    aux2: Buffer,
    partials: Buffer,
    solve: Buffer,
    /// The step's neighbour lists (dfsph, see glsl/sph/dfsph.comp): one u32 when off.
    nb_list: Buffer,
    /// Particle-steps whose neighbours overflowed their list, over the state's life.
    overflow: Buffer,
}

impl PressureBuffers {
    /// For `capacity` particles, lists of `list_len` neighbours (0: none).
    pub fn new(ctx: &Context, capacity: u64, list_len: u32) -> Result<Self> {
        let n = capacity.max(1);
        let aux = Guard::new(ctx, ctx.storage_buffer("pressure aux", n * 16)?);
        let aux2 = Guard::new(ctx, ctx.storage_buffer("pressure aux2", n * 16)?);
        let partials = Guard::new(
            ctx,
            ctx.storage_buffer("pressure partials", n.div_ceil(LOCAL_SIZE as u64) * 16)?,
        );
        let nb_list = Guard::new(
            ctx,
            ctx.storage_buffer("neighbour lists", (n * list_bytes(list_len)).max(4))?,
        );
        let overflow = Guard::new(
            ctx,
            ctx.create_buffer(
                "neighbour list overflows",
                4,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                crate::gpu::MemoryLocation::GpuToCpu,
            )?,
        );
        ctx.one_shot(|cmd| ctx.fill(cmd, &overflow, 0))?;
        // Every solve writes its iterations and error at each iteration; a solver without
        // a divergence solve reports 0 for it.
        let solve = ctx.create_buffer(
            "pressure solve state",
            std::mem::size_of::<SolveState>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::INDIRECT_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            crate::gpu::MemoryLocation::GpuOnly,
        )?;
        let solve = Guard::new(ctx, solve);
        ctx.one_shot(|cmd| ctx.fill(cmd, &solve, 0))?;
        Ok(Self {
            aux: aux.take(),
            aux2: aux2.take(),
            partials: partials.take(),
            solve: solve.take(),
            nb_list: nb_list.take(),
            overflow: overflow.take(),
        })
    }

    /// Particle-steps whose neighbours overflowed their list so far (read after the
    /// device is idle or the last step's fence; the counter is host-visible memory).
    pub fn list_overflows(&self) -> u64 {
        self.overflow.mapped().map_or(0, |raw| {
            bytemuck::pod_read_unaligned::<u32>(&raw[..4]) as u64
        })
    }

    /// The solve state (iterations and errors of the current step).
    pub fn solve(&self) -> &Buffer {
        &self.solve
    }
    pub fn aux2(&self) -> &Buffer {
        &self.aux2
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.aux,
            &mut self.aux2,
            &mut self.partials,
            &mut self.solve,
            &mut self.nb_list,
            &mut self.overflow,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}

impl SphState {
    /// Iterations a solve records this step: the state's bound (set from earlier steps'
    /// counts by the Stepper), else max_iter; at least min_iter.
    pub fn recorded_iterations(&self, divergence: bool) -> u32 {
        let c = self.fluid.convergence();
        match self.iteration_bound[divergence as usize] {
            0 => c.max_iterations,
            b => b.clamp(c.min_iterations.max(1), c.max_iterations),
        }
    }

    /// See [`PressureBuffers::list_overflows`]; 0 for wcsph.
    pub fn list_overflows(&self) -> u64 {
        self.pressure.as_ref().map_or(0, |p| p.list_overflows())
    }

    pub fn pressure(&self) -> Result<&PressureBuffers> {
        self.pressure.as_ref().ok_or_else(|| {
            Error::Param(format!(
                "solver {} on a state made for wcsph: make the state with the solver set",
                self.fluid.solver.as_str()
            ))
        })
    }

    pub fn pressure_bufs(&self) -> Result<PressureBufs<'_>> {
        let p = self.pressure()?;
        let b = self.bufs();
        Ok(PressureBufs {
            params: b.params,
            nb_keys: b.nb_keys,
            nb_start: b.nb_start,
            nb_end: b.nb_end,
            nb_box: b.nb_box,
            pos: b.pos,
            vel: b.vel,
            rho_p: b.rho_p,
            acc: b.acc,
            vhalf: b.vhalf,
            colliders: b.colliders,
            aux: &p.aux,
            aux2: &p.aux2,
            partials: &p.partials,
            solve: &p.solve,
            nb_list: &p.nb_list,
            overflow: &p.overflow,
            clock: &self.clock,
            params_out: b.params,
        })
    }
}

crate::impl_destroy!(Pipelines, PressureBuffers);

/// When a pressure solve stops: the chosen solver's targets and iteration bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    /// Mean density error (rho / rho_0 - 1 where compressed) the solve iterates down to.
    pub density_error: f32,
    /// dfsph: mean compression rate times dt the divergence solve iterates down to.
    pub divergence_error: f32,
    pub min_iterations: u32,
    pub max_iterations: u32,
    /// The density solve stops once its own estimate is at most this fraction of
    /// `density_error` (1: at the target; DFSPH's [`stop_fraction`](super::dfsph::DfsphParams)).
    pub stop_fraction: f32,
}

/// `fluid.TABLE.NAME` must lie in lo..=hi.
pub(crate) fn check_range(table: &str, name: &str, v: f32, (lo, hi): (f32, f32)) -> Result<()> {
    match v >= lo && v <= hi {
        true => Ok(()),
        false => Err(Error::Param(format!(
            "fluid.{table}.{name} must be in {lo}..={hi}, got {v}"
        ))),
    }
}

/// A solver table's own step (`cfl`, `dt_max`), in range (cfl 0: none, fixed steps).
pub(crate) fn check_step(table: &str, cfl: f32, dt_max: f32) -> Result<()> {
    if cfl != 0.0 {
        check_range(table, "cfl", cfl, (1e-3, 1.0))?;
    }
    check_range(table, "dt_max", dt_max, (1e-6, 1.0))
}

/// 1 <= min <= max <= MAX_ITERATIONS for `fluid.TABLE`.
pub(crate) fn check_iterations(table: &str, min: u32, max: u32) -> Result<()> {
    use super::params::MAX_ITERATIONS;
    match min >= 1 && min <= max && max <= MAX_ITERATIONS {
        true => Ok(()),
        false => Err(Error::Param(format!(
            "fluid.{table}: need 1 <= min_iterations ({min}) <= max_iterations ({max}) <= \
             {MAX_ITERATIONS}"
        ))),
    }
}
