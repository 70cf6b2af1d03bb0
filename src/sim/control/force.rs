//! The driving force (seed 000, eq. 7) as an SPH force hook: per frame the control
//! particles are skinned to the pose (`skin`), binned on their own grid (cell h_c) by the
//! counting sort (`control-grid`); per step the fluid density at each control particle
//! (`control-density`, over the fluid grid) and the force on each fluid particle
//! (`control-force`, over the control grid), with adaptive control pressure and an
//! optional velocity term.
use super::cache::ForceCache;
use super::passes::{
    ControlKey, CONTROL_AGGREGATE, CONTROL_DENSITY, CONTROL_FIELD, CONTROL_FORCE,
    CONTROL_FORCE_STORED,
};
pub use super::settings::ControlSettings;
use crate::character::pose::GpuJoint;
use crate::character::skin::{SkinPass, SkinnedMesh};
use crate::character::Mesh;
use crate::error::{Error, Result};
use crate::gpu::{vk, Buffer, ComputePipeline, Context, Guard, Open, ScopeName, Scopes};
use crate::kinds::{Neighbors, SortAlgo};
use crate::primitives::counting::GatherPass;
use crate::primitives::neighbors::{GridSpec, NeighborBuffers, NeighborSearch};
use crate::sph::hooks::SphHook;
use crate::sph::solver::SphState;

const CONTROL_GRID_SCOPE: ScopeName = ScopeName::new("control-grid");

pub use super::interface::{ControlBufs, ControlGpuParams, ControlIo, LIVE_OFFSET};

/// Every group is controlled.
pub const ALL_GROUPS: u32 = u32::MAX;

/// A frame's pose for the control particles: rest-relative joint matrices and the frame
/// time (for their velocity).
pub struct Pose {
    pub joints: Vec<GpuJoint>,
    /// The morph targets' weights (empty where the set has none).
    pub weights: Vec<f32>,
    pub frame_dt: f32,
    /// `--control-motion skin`: the joints and weights a frame ahead (the velocity is the
    /// skin's motion over the frame the steps cover, not the last frame's).
    pub next: Option<(Vec<GpuJoint>, Vec<f32>)>,
}

/// How a control set is placed and skinned: `--placement rays` (spacing, capacity), the
/// skinning, and each control particle's fill of the shape (`--control-deficit shape`).
pub type SetKind<'a> = (
    Option<(f32, u32)>,
    crate::character::Skinning,
    Option<&'a [f32]>,
);

/// GPU state of a control set.
struct ControlGpu {
    density: ComputePipeline<ControlIo>,
    aggregate: ComputePipeline<ControlIo>,
    field: ComputePipeline<ControlIo>,
    force: ComputePipeline<ControlIo>,
    /// The force pass between refreshes (`--control-every`): stored sums applied.
    apply: ComputePipeline<ControlIo>,
    /// Made at the first step, for the fluid's capacity.
    cache: Option<ForceCache>,
    skin: SkinPass,
    mesh: SkinnedMesh,
    search: NeighborSearch,
    nb: NeighborBuffers,
    grid: GridSpec,
    /// The grid the control set is sorted on: cells of h_c / 2, twice the dims (eq. 7's
    /// walk visits a third of the candidates of 27 cells of h_c; see force.comp).
    fine: GridSpec,
    gather: GatherPass,
    prev: Buffer,
    sorted_pos: Buffer,
    sorted_prev: Buffer,
    crho: Buffer,
    /// Per control particle (density.comp): its velocity and eq. 7 weight, what eq. 7's
    /// walk reads of it besides its position (one read instead of three).
    cvw: Buffer,
    /// Per control-grid cell: the sums of aggregate.comp (3 vec4).
    cagg: Buffer,
    /// Per cell centre: the attraction and damping field of field.comp (2 vec4).
    cfield: Buffer,
    params: Buffer,
    /// `--placement rays`: re-placed from the skinned mesh (`mesh`) every frame.
    rays: Option<super::rays::RaysPlacer>,
}

crate::impl_destroy!(ControlGpu);
impl ControlGpu {
    fn destroy(&mut self, ctx: &Context) {
        self.density.destroy(ctx);
        self.aggregate.destroy(ctx);
        self.field.destroy(ctx);
        self.force.destroy(ctx);
        self.apply.destroy(ctx);
        if let Some(c) = &mut self.cache {
            c.destroy(ctx);
        }
        self.skin.destroy(ctx);
        self.mesh.destroy(ctx);
        self.search.destroy(ctx);
        self.nb.destroy(ctx);
        self.gather.destroy(ctx);
        if let Some(r) = &mut self.rays {
            r.destroy(ctx);
        }
        for b in [
            &mut self.prev,
            &mut self.sorted_pos,
            &mut self.sorted_prev,
            &mut self.crho,
            &mut self.cvw,
            &mut self.cagg,
            &mut self.cfield,
            &mut self.params,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}

/// The control force: owned by the scene, which feeds it poses and lends it to the
/// frame's steps as a force hook.
pub struct ControlForce {
    gpu: ControlGpu,
    pending: Option<Pose>,
    /// No pose recorded yet: the first one is also the previous (zero velocity).
    first: bool,
    /// Attached (the hook records nothing while released) and the factor on c_cp.
    attached: bool,
    strength: f32,
    pub settings: ControlSettings,
    /// Control particles.
    pub m: u32,
}

/// How many control particles the force holds (the rays' capacity or the mesh's
/// vertices), after the settings' checks.
fn control_count(
    mesh: &Mesh,
    settings: &ControlSettings,
    rays: Option<(f32, u32)>,
) -> Result<usize> {
    settings.validate()?;
    let m = match rays {
        Some((_, capacity)) => capacity as usize,
        None => mesh.vertices(),
    };
    if m == 0 {
        return Err(Error::Param("no control particles".into()));
    }
    if rays.is_some() && (settings.velocity > 0.0 || settings.damping > 0.0) {
        return Err(Error::Param(
            "--control-velocity and --control-damping need control particles that persist between frames: --placement rays re-places them every frame (use vertices or random, or set both to 0)".into(),
        ));
    }
    // The control grid: the grid strategy with the counting sort (cell counts).
    let (kind, sort) = (Neighbors::Grid, SortAlgo::Counting);
    if !NeighborSearch::defines_for(kind, sort).contains(&("NB_CELL_COUNTS", "1".into())) {
        return Err(Error::Param(
            "the control grid expects cell counts from the counting sort".into(),
        ));
    }
    Ok(m)
}

impl ControlForce {
    /// For control particles at rest positions `mesh.positions`, bound by its joints and
    /// weights (normals unused), skinned by `joints` joints, for fluid searched by
    /// `solver`, in the domain [lo, hi], skinned by `skinning`. With `rays` (spacing,
    /// capacity), `mesh` is the target's surface, skinned and re-placed by rays every frame.
    /// `fill`: per control particle, the fraction of rest density the shape's own fill
    /// gives there (`--control-deficit shape`; None: rest density).
    /// Long because each pipeline and buffer is made under its own guard and moved into
    /// the force at the end (a failure part-way frees what was made).
    pub fn new(
        ctx: &Context,
        solver: &crate::sph::SphSolver,
        mesh: &Mesh,
        joints: usize,
        settings: ControlSettings,
        domain: ([f32; 3], [f32; 3]),
        (rays, skinning, fill): SetKind,
    ) -> Result<Self> {
        let m = control_count(mesh, &settings, rays)?;
        let (kind, sort) = (Neighbors::Grid, SortAlgo::Counting);
        // The passes walk the fluid's grid with the fluid search's defines.
        let key = ControlKey {
            search: solver.search.key(),
            adaptive: settings.adaptive,
        };
        let pipeline = |p: Result<ComputePipeline<ControlIo>>| p.map(|p| Guard::new(ctx, p));
        let density = pipeline(CONTROL_DENSITY.pipeline(ctx, &key, 64, &[]))?;
        let aggregate = pipeline(CONTROL_AGGREGATE.pipeline(ctx, &key, 64, &[]))?;
        let field = pipeline(CONTROL_FIELD.pipeline(ctx, &key, 64, &[]))?;
        let force = pipeline(CONTROL_FORCE.pipeline(ctx, &key, 64, &[]))?;
        let apply = pipeline(CONTROL_FORCE_STORED.pipeline(ctx, &key, 64, &[]))?;
        // Rays: three more layers above the domain in z, the last one parking the unused
        // slots two cells away from any fluid particle's.
        let r = settings.radius;
        let spacing = rays.map_or(0.0, |(s, _)| s);
        // (Lattice steps reach half a spacing past the domain's top.)
        let top = [domain.1[0], domain.1[1], domain.1[2] + spacing + 3.0 * r];
        let hi = if rays.is_some() { top } else { domain.1 };
        let grid = GridSpec::covering(domain.0, hi, r)?;
        let fine = grid.halved()?;
        let rays = match rays {
            Some((spacing, capacity)) => {
                let g = super::rays::RaysGrid::new(domain.0, domain.1, spacing)?;
                let far = domain
                    .0
                    .iter()
                    .chain(&domain.1)
                    .fold(0f32, |a, v| a.max(v.abs()));
                let park = far + spacing + 3.0 * r + 1.0;
                Some(Guard::new(
                    ctx,
                    super::rays::RaysPlacer::new(ctx, g, capacity, park)?,
                ))
            }
            None => None,
        };
        let search = Guard::new(ctx, NeighborSearch::new(ctx, kind, Some(sort))?);
        let nb = Guard::new(ctx, search.buffers(ctx, m as u64, &fine, 0)?);
        let skin = SkinPass::new(ctx, skinning, mesh.influence_sets)?;
        let skin = Guard::new(ctx, skin);
        let cmesh = Guard::new(ctx, SkinnedMesh::tagged(ctx, mesh, joints, fill)?);
        let gather = Guard::new(ctx, GatherPass::new(ctx)?);
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let v4 = m as u64 * 16;
        // (Rays keep no previous pose.)
        let prev = buf("control previous", if rays.is_some() { 16 } else { v4 })?;
        let sorted_pos = buf("control sorted positions", v4)?;
        let sorted_prev = buf("control sorted previous", v4)?;
        let crho = buf("control densities", m as u64 * 4)?;
        let cvw = buf("control velocities and weights", v4)?;
        let cagg = buf("control cell sums", grid.cells() * 48)?;
        let cfield = buf("control field", grid.cells() * 32)?;
        let params = buf(
            "control params",
            std::mem::size_of::<ControlGpuParams>() as u64,
        )?;
        Ok(Self {
            gpu: ControlGpu {
                density: density.take(),
                aggregate: aggregate.take(),
                field: field.take(),
                force: force.take(),
                apply: apply.take(),
                cache: None,
                skin: skin.take(),
                mesh: cmesh.take(),
                search: search.take(),
                nb: nb.take(),
                grid,
                fine,
                gather: gather.take(),
                prev: prev.take(),
                sorted_pos: sorted_pos.take(),
                sorted_prev: sorted_prev.take(),
                crho: crho.take(),
                cvw: cvw.take(),
                cagg: cagg.take(),
                cfield: cfield.take(),
                params: params.take(),
                rays: rays.map(|r| r.take()),
            },
            pending: None,
            first: true,
            attached: true,
            strength: 1.0,
            settings,
            m: m as u32,
        })
    }

    /// The pose the next step uses (once per frame).
    pub fn set_pose(&mut self, pose: Pose) {
        self.pending = Some(pose);
    }

    /// Attach or release (a released set records no passes; when attached again its
    /// first pose has zero velocity) at `strength` times c_cp, from the next pose on.
    pub fn set_attached(&mut self, attached: bool, strength: f32) {
        if attached && !self.attached {
            self.first = true;
        }
        if !attached {
            self.pending = None;
        }
        self.attached = attached;
        self.strength = strength;
    }

    pub fn attached(&self) -> bool {
        self.attached
    }

    /// `ahead`: the previous-pose buffer holds the pose a frame ahead (skin motion), so
    /// the velocity (cpos - cprev) / frame_dt changes sign.
    fn gpu_params(&self, g: &ControlGpu, frame_dt: f32, ahead: bool) -> ControlGpuParams {
        let s = &self.settings;
        let h = s.radius;
        ControlGpuParams {
            grid: [
                g.grid.origin[0],
                g.grid.origin[1],
                g.grid.origin[2],
                g.grid.cell,
            ],
            dims: [g.grid.dims[0], g.grid.dims[1], g.grid.dims[2], self.m],
            pressure: s.pressure * self.strength,
            radius: h,
            spiky_grad: -45.0 / (std::f32::consts::PI * h.powi(6)),
            velocity: s.velocity,
            adaptive: ControlSettings::adaptive_id(s.adaptive),
            low: s.low,
            high: s.high,
            up: s.up,
            down: s.down,
            inv_frame: match (frame_dt > 0.0, ahead) {
                (false, _) => 0.0,
                (true, false) => 1.0 / frame_dt,
                (true, true) => -1.0 / frame_dt,
            },
            group: s.group,
            live: self.m,
            attraction: s.attraction,
            reach: s.reach,
            reach_cells: (s.reach / g.grid.cell).ceil() as u32,
            damping: s.damping,
        }
    }

    /// Skin to `pose`, bin, and sort the control set (once per frame); `first`: the
    /// first pose since attached (it is its own previous pose).
    fn record_pose(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        pose: &Pose,
        first: bool,
    ) -> Result<()> {
        let g = &self.gpu;
        let bytes = self.m as u64 * 16;
        // (Rays: the surface is skinned, not the particles; they have no other pose.)
        let ahead = pose.next.as_ref().filter(|_| g.rays.is_none());
        {
            let _scope = scopes.open(ctx, cmd, crate::character::skin::SKIN.scope());
            if !first && g.rays.is_none() && ahead.is_none() {
                ctx.copy(cmd, &g.mesh.pos, 0, &g.prev, 0, bytes);
            }
            let params = self.gpu_params(g, pose.frame_dt, ahead.is_some());
            ctx.update(cmd, &g.params, 0, &[params]);
            // Morph weights where the set carries targets (the rays' surface, or particles
            // bound to a morphing mesh).
            let weights = |w: &[f32]| match g.mesh.targets > 0 && !w.is_empty() {
                true => g.mesh.set_weights(ctx, cmd, w),
                false => Ok(()),
            };
            if let Some((next, w)) = ahead {
                // The pose a frame ahead, skinned into `prev`, then the frame's own.
                g.mesh.set_pose(ctx, cmd, next)?;
                weights(w)?;
                g.skin.record(ctx, cmd, &g.mesh)?;
                ctx.copy(cmd, &g.mesh.pos, 0, &g.prev, 0, bytes);
            }
            g.mesh.set_pose(ctx, cmd, &pose.joints)?;
            weights(&pose.weights)?;
            g.skin.record(ctx, cmd, &g.mesh)?;
            // Re-placed particles have no previous pose: both are the new set.
            if g.rays.is_none() && first && ahead.is_none() {
                ctx.copy(cmd, &g.mesh.pos, 0, &g.prev, 0, bytes);
            }
        }
        // The control set and its previous pose: the skinned particles, or the rays
        // placement's.
        let (pos, prev) = match &g.rays {
            Some(r) => {
                r.record(
                    ctx,
                    cmd,
                    scopes,
                    &g.mesh.pos,
                    &g.mesh.indices,
                    g.mesh.triangles,
                )?;
                ctx.copy(
                    cmd,
                    &r.stats,
                    super::rays::STATS_PARTICLES,
                    &g.params,
                    LIVE_OFFSET,
                    4,
                );
                (&r.out, &r.out)
            }
            None => (&g.mesh.pos, &g.prev),
        };
        {
            let mut scopes = scopes.open(ctx, cmd, CONTROL_GRID_SCOPE);
            g.search
                .record_build(ctx, cmd, &mut *scopes, &g.nb, pos, self.m, &g.fine)?;
            g.gather
                .record(ctx, cmd, &g.nb.perm, pos, &g.sorted_pos, self.m);
            g.gather
                .record(ctx, cmd, &g.nb.perm, prev, &g.sorted_prev, self.m);
        }
        Ok(())
    }

    fn bufs<'a>(
        &self,
        g: &'a ControlGpu,
        st: &'a SphState,
        (cforce, cvmean): (&'a Buffer, &'a Buffer),
    ) -> ControlBufs<'a> {
        let s = st.bufs();
        let (cstart, ccount) = g.nb.cell_buffers();
        ControlBufs {
            params: s.params,
            nb_keys: s.nb_keys,
            nb_start: s.nb_start,
            nb_end: s.nb_end,
            nb_box: s.nb_box,
            pos: s.pos,
            vel: s.vel,
            rho_p: s.rho_p,
            acc: s.acc,
            vhalf: s.vhalf,
            colliders: s.colliders,
            control: &g.params,
            cpos: &g.sorted_pos,
            cprev: &g.sorted_prev,
            crho: &g.crho,
            cvw: &g.cvw,
            cstart,
            ccount,
            attr: st.attr(),
            cagg: &g.cagg,
            cfield: &g.cfield,
            cforce,
            cvmean,
        }
    }

    /// Fluid density at the control particles of the last step (sorted by the control
    /// grid), read after the frame's fence.
    pub fn densities(&self, ctx: &Context) -> Result<Vec<f32>> {
        ctx.readback(&self.gpu.crho, 0, self.m as usize)
    }

    /// Record copies of the control densities into `crho` and of the counts into
    /// `counts` (16 bytes: live control particles, then the rays placement's fragments and
    /// particles) (host-visible buffers; the caller orders them after the steps and before
    /// the host reads).
    pub fn record_copy_readback(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        crho: &Buffer,
        counts: &Buffer,
    ) -> Result<()> {
        let g = &self.gpu;
        ctx.copy(cmd, &g.crho, 0, crho, 0, self.m as u64 * 4);
        ctx.copy(cmd, &g.params, LIVE_OFFSET, counts, 0, 4);
        if let Some(r) = &g.rays {
            ctx.copy(cmd, &r.stats, 0, counts, 4, 8);
        }
        Ok(())
    }

    /// The live control particles of a frame's counts (see `record_copy_readback`), or
    /// the rays placement's overflow.
    pub fn check_counts(&self, counts: [u32; 4]) -> Result<u32> {
        if let Some(r) = &self.gpu.rays {
            r.check(counts[1], counts[2])?;
        }
        Ok(counts[0].min(self.m))
    }

    /// Re-placed every frame (`--placement rays`).
    pub fn replaced(&self) -> bool {
        self.gpu.rays.is_some()
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.gpu.destroy(ctx);
    }
}

/// The control force's timestamp scope: a hook inside the SPH step.
pub const SCOPE: crate::gpu::ScopeKey = crate::gpu::ScopeKey::new("sph/control");

/// The control force as a force hook of the SPH step (scope `SCOPE`).
impl SphHook for ControlForce {
    fn scope(&self) -> crate::gpu::ScopeName {
        SCOPE.scope()
    }

    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        st: &SphState,
    ) -> Result<()> {
        if !self.attached {
            return Ok(());
        }
        let posed = match self.pending.take() {
            Some(pose) => {
                let first = std::mem::replace(&mut self.first, false);
                self.record_pose(ctx, cmd, scopes, &pose, first)?;
                true
            }
            None if self.first => {
                return Err(Error::Param(
                    "control particles stepped before their first pose".into(),
                ))
            }
            None => false,
        };
        let cache = match &mut self.gpu.cache {
            Some(c) => c,
            none => none.insert(ForceCache::new(ctx, st.particles.capacity)?),
        };
        let refresh = cache.step(st, self.settings.every, posed)?;
        let push = st.neighbor_push();
        let (c, g) = (&*self, &self.gpu);
        let Some(cache) = g.cache.as_ref() else {
            return Err(Error::Bug("control force cache missing".into()));
        };
        let bufs = c.bufs(g, st, cache.current());
        if !refresh {
            // The last step's stored sums, gathered into this step's particle order.
            {
                let _scope = scopes.open(ctx, cmd, CONTROL_FORCE_STORED.scope());
                g.gather
                    .record_many(ctx, cmd, &st.nb.perm, &cache.gathers(), st.n);
                g.apply.dispatch(ctx, cmd, &bufs, &push, st.n as u64);
            }
            return Ok(());
        }
        {
            let _scope = scopes.open(ctx, cmd, CONTROL_DENSITY.scope());
            g.density.dispatch(ctx, cmd, &bufs, &push, c.m as u64);
        }
        let s = &c.settings;
        // The attraction and damping field follows the pose (once a frame): refreshed at
        // every eq. 7 refresh it cost 0.05 of the step on the walker and changed no metric.
        if (s.attraction > 0.0 || s.damping > 0.0) && posed {
            {
                let _scope = scopes.open(ctx, cmd, CONTROL_AGGREGATE.scope());
                g.aggregate.dispatch(ctx, cmd, &bufs, &push, g.grid.cells());
            }
            {
                let _scope = scopes.open(ctx, cmd, CONTROL_FIELD.scope());
                g.field.dispatch(ctx, cmd, &bufs, &push, g.grid.cells());
            }
        }
        {
            let _scope = scopes.open(ctx, cmd, CONTROL_FORCE.scope());
            g.force.dispatch(ctx, cmd, &bufs, &push, st.n as u64);
        }
        Ok(())
    }

    fn destroy(&mut self, ctx: &Context) {
        ControlForce::destroy(self, ctx);
    }
}
