//! The incompressible solvers' shared machinery (pcisph.rs, dfsph.rs, pbf.rs): their extra
//! per-particle buffers, their passes (one table, also read by the every-shader-compiles
//! registry), and the iteration loop. A solve records `max_iter` iterations; each ends in
//! a one-workgroup pass (solve_loop.comp) that reduces the iteration's error on the GPU and,
//! once the solve has converged, zeroes the group count of the indirect dispatches that
//! remain: no read-back per iteration, and skipped iterations cost an empty dispatch.
use super::solver::{SphSolver, SphState, LOCAL_SIZE};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputeDesc, ComputePipeline, Context, Guard, Scopes};
use crate::kinds::Solver;
use crate::primitives::neighbors::NeighborPush;
use bytemuck::{Pod, Zeroable};

crate::gpu_interface! {
    /// glsl/sph/pressure.glsl: SphIo's bindings (same numbers), then the pressure solvers'.
    pub PressureIo / PressureBufs: "SPH", push NeighborPush {
        params = 0, nb_keys = 1, nb_start = 2, nb_end = 3, nb_box = 4,
        pos = 5, vel = 6, rho_p = 7, acc = 8, vhalf = 9, colliders = 10,
        aux = 11, aux2 = 12, partials = 13, solve = 14, nb_list = 15, overflow = 16,
    }
}

/// Mirror of `SolveState` in glsl/sph/pressure.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct SolveState {
    /// The iteration passes' VkDispatchIndirectCommand; `gz` is 0 once converged.
    pub gx: u32,
    pub gy: u32,
    pub gz: u32,
    pub iter: u32,
    pub done: u32,
    /// The loop pass's own VkDispatchIndirectCommand (1, 1, 1); `lz` is 0 once converged.
    pub lx: u32,
    pub ly: u32,
    pub lz: u32,
    pub density_iters: u32,
    pub divergence_iters: u32,
    /// The solves' own error estimates at their last iteration.
    pub density_err: f32,
    pub divergence_err: f32,
}
const _: () = assert!(std::mem::size_of::<SolveState>() == 48);

/// Byte offset of the loop pass's dispatch (lx) in SolveState.
const LOOP_ARGS_OFFSET: u64 = 20;
const _: () = assert!(std::mem::offset_of!(SolveState, lx) == LOOP_ARGS_OFFSET as usize);

/// Bytes per particle the pressure solvers add (aux, aux2), besides the neighbour list.
pub const BYTES_PER_PARTICLE: u64 = 32;

/// Bytes per particle of a neighbour list of `len` entries (and its count).
pub fn list_bytes(len: u32) -> u64 {
    match len {
        0 => 0,
        k => 4 * (k as u64 + 1),
    }
}

/// A pass: (name, shader, PASS, DIVERGENCE).
pub type PassDecl = (&'static str, &'static str, &'static str, bool);

pub const LOOP_DENSITY: PassDecl = ("loop/density", "sph/solve_loop.comp", "PASS_LOOP", false);
pub const LOOP_DIVERGENCE: PassDecl = ("loop/divergence", "sph/solve_loop.comp", "PASS_LOOP", true);
pub const EULER: PassDecl = ("euler", "sph/euler.comp", "PASS_EULER", false);

/// A solver's constructor (`base`: the neighbour search's and the EOS's defines).
type Make = fn(&Context, &[(&str, String)]) -> Result<Box<dyn PressureSolver>>;

/// Each solver's pass table and constructor: its one registration line.
fn registered(kind: Solver) -> (&'static [PassDecl], Make) {
    use super::{dfsph::Dfsph, pbf::Pbf, pcisph::Pcisph, wcsph::Wcsph};
    match kind {
        Solver::Wcsph => (&[], |_, _| Ok(Box::new(Wcsph))),
        Solver::Pcisph => (&super::pcisph::PASSES, |c, b| {
            Ok(Box::new(Pcisph::new(c, b)?))
        }),
        Solver::Dfsph => (&super::dfsph::PASSES, |c, b| {
            Ok(Box::new(Dfsph::new(c, b)?))
        }),
        Solver::Pbf => (&super::pbf::PASSES, |c, b| Ok(Box::new(Pbf::new(c, b)?))),
    }
}

/// The passes of each solver (the every-shader-compiles registry reads them too).
pub fn passes(solver: Solver) -> Vec<PassDecl> {
    registered(solver).0.to_vec()
}

/// Build `kind`'s passes (`base`: the neighbour search's and the EOS's defines).
pub fn build(
    ctx: &Context,
    kind: Solver,
    base: &[(&str, String)],
) -> Result<Box<dyn PressureSolver>> {
    (registered(kind).1)(ctx, base)
}

/// A pressure solver: what a step records after the arrange. The base passes (density,
/// forces, integrate) are `SphSolver`'s; a solver adds its own around them.
pub trait PressureSolver {
    fn kind(&self) -> Solver;

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

const PASS_NAMES: [&str; 15] = [
    "PASS_PREDICT",
    "PASS_PRESSURE",
    "PASS_ACCEL",
    "PASS_FACTOR",
    "PASS_WARM",
    "PASS_SOURCE",
    "PASS_VELOCITY",
    "PASS_LAMBDA",
    "PASS_DELTA",
    "PASS_APPLY",
    "PASS_VORTICITY",
    "PASS_CONFINE",
    "PASS_LOOP",
    "PASS_EULER",
    "PASS_FORCES",
];

/// Local size of the loop pass (one workgroup).
const LOOP_WG: u32 = 256;

/// The defines of one pass, on top of the neighbour search's and the EOS's.
pub fn pass_defines(d: &PassDecl) -> Vec<(String, String)> {
    let mut v: Vec<(String, String)> = PASS_NAMES
        .iter()
        .enumerate()
        .map(|(k, n)| (n.to_string(), (k + 1).to_string()))
        .collect();
    v.push(("PASS".into(), d.2.into()));
    v.push(("DIVERGENCE".into(), (d.3 as u32).to_string()));
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
    /// `base`: the neighbour search's and the EOS's defines.
    pub fn new(
        ctx: &Context,
        solver: Solver,
        table: &'static [PassDecl],
        base: &[(&str, String)],
    ) -> Result<Self> {
        let mut out = Guard::new(
            ctx,
            Self {
                table,
                list: Vec::new(),
            },
        );
        for d in table {
            let own = pass_defines(d);
            let mut defines: Vec<(&str, String)> = base.to_vec();
            defines.extend(crate::gpu::pipeline::as_refs(&own));
            let local = if d.2 == "PASS_LOOP" {
                LOOP_WG
            } else {
                LOCAL_SIZE
            };
            let label = format!("{}/{}", solver.as_str(), d.0);
            let p = ComputePipeline::new(ctx, &ComputeDesc::plain(&label, d.1, &defines, local))?;
            out.list.push(p);
        }
        Ok(out.take())
    }

    /// Pass `k` of the table: its name (the timestamp scope) and pipeline.
    fn pass(&self, k: usize) -> (&'static str, &ComputePipeline<PressureIo>) {
        (self.table[k].0, &self.list[k])
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
        scopes.begin(ctx, cmd, self.pass(k).0);
        let r = self.run(ctx, cmd, st, k);
        scopes.end(ctx, cmd);
        r
    }

    /// An iterative solve in the scope `scope`: the `body` passes per iteration (the one
    /// that reduces the error among them), then the loop pass `check`, `max_iter` times;
    /// `divergence`: the divergence solve (its own iteration bound).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
        scope: &str,
        (body, check): (&[usize], usize),
        divergence: bool,
    ) -> Result<()> {
        let b = st.pressure_bufs()?;
        let solve = st.pressure()?.solve();
        let push = st.neighbor_push();
        let groups = (st.n as u64).div_ceil(LOCAL_SIZE as u64).max(1);
        let gx = groups.min(crate::gpu::pipeline::MAX_GROUPS_X as u64) as u32;
        let gy = groups.div_ceil(gx as u64) as u32;
        let c = st.fluid.convergence();
        let (min_iter, max_iter) = (c.min_iterations, c.max_iterations);
        // The iterations recorded: the state's bound (set from earlier steps' counts by
        // the Stepper), else max_iter.
        let recorded = match st.iteration_bound[divergence as usize] {
            0 => max_iter,
            b => b.clamp(min_iter.max(1), max_iter),
        };
        scopes.begin(ctx, cmd, scope);
        ctx.update(cmd, solve, 0, &[gx, gy, 1, 0, 0, 1, 1, 1]);
        let check = self.pass(check).1;
        let body: Vec<_> = body.iter().map(|k| self.pass(*k).1).collect();
        for _ in 0..recorded {
            for p in &body {
                p.dispatch_indirect(ctx, cmd, &b, &push, solve, 0);
            }
            check.dispatch_indirect(ctx, cmd, &b, &push, solve, LOOP_ARGS_OFFSET);
        }
        scopes.end(ctx, cmd);
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
        let solve = ctx.create_buffer(
            "pressure solve state",
            std::mem::size_of::<SolveState>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::INDIRECT_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            crate::gpu::MemoryLocation::GpuOnly,
        )?;
        Ok(Self {
            aux: aux.take(),
            aux2: aux2.take(),
            partials: partials.take(),
            solve,
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

    /// Zero the step's solve statistics (a step that solves nothing reports 0).
    pub fn record_reset(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        ctx.update(cmd, &self.solve, 0, &[SolveState::default()]);
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
