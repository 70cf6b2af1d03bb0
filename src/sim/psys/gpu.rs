//! The GPU side of a particle system: the parameter block and counters (mirrored in
//! glsl/psys/common.glsl), the passes' interfaces and pipelines (size-independent).
use super::codes;
use super::spec::{
    BoidsSpec, ColliderKind, EventKind, ForceKind, Shape, SystemSpec, MAX_COLLIDERS, MAX_FORCES,
    MAX_KEYS,
};
use crate::error::Result;
use crate::gpu::pass::{Defines, PassKey};
use crate::gpu::target::{COLOR_FORMAT, DEPTH_FORMAT};
use crate::gpu::vk;
use crate::gpu::{
    Buffer, ComputePipeline, Context, GraphicsPipeline, GraphicsStates, Guard, ScopeName,
};
use crate::kinds::Neighbors;
use crate::kinds::SortAlgo;
use crate::primitives::counting::CountingSort;
use crate::primitives::neighbors::NbKey;
use crate::primitives::neighbors::{GridSpec, NeighborSearch};
use crate::primitives::scan::{ScanPass, ScanVariant};
use crate::primitives::sort::{Network, NetworkSort};
use crate::psys::{Integrator, SpriteMode};
use bytemuck::{Pod, Zeroable};

type V4 = [f32; 4];

/// `SystemParams` of glsl/psys/common.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct SystemParams {
    pub emitter: V4,
    pub extent: V4,
    pub normal: V4,
    pub offset_mean: V4,
    pub offset_var: V4,
    pub vel_mean: V4,
    pub vel_var: V4,
    pub color_mean: V4,
    pub color_var: V4,
    pub scalar_mean: V4,
    pub scalar_var: V4,
    pub gravity: V4,
    pub wind: V4,
    pub death: V4,
    pub counts: [u32; 4],
    pub counts2: [u32; 4],
    pub size_keys: [V4; MAX_KEYS],
    pub color_keys: [V4; MAX_KEYS],
    pub opacity_keys: [V4; MAX_KEYS],
    pub forces: [[V4; 2]; MAX_FORCES],
    pub colliders: [[V4; 3]; MAX_COLLIDERS],
    pub boids: [V4; 4],
    pub grid_dims: [u32; 4],
}
const _: () =
    assert!(std::mem::size_of::<SystemParams>() == 16 * 16 + 3 * 8 * 16 + 8 * 32 + 8 * 48 + 5 * 16);

/// `Counters` of glsl/psys/common.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq, Eq)]
pub struct Counters {
    pub dead_count: i32,
    pub alive: [u32; 2],
    pub verts: u32,
    pub update_args: [u32; 4],
    pub draw_args: [u32; 4],
    pub births: u32,
    pub refused: u32,
    pub died_life: u32,
    pub died_view: u32,
    pub died_distance: u32,
    pub died_collision: u32,
    pub overwritten: u32,
    /// Parents that died by a collision event (their type changed).
    pub changed: u32,
    /// Births from other systems' events.
    pub spawned: u32,
    /// Children refused: no free slot.
    pub spawn_refused: u32,
    /// Events lost: the event list was full.
    pub events_dropped: u32,
    pub pad: u32,
}
const _: () = assert!(std::mem::size_of::<Counters>() == 96);

impl Counters {
    pub const UPDATE_ARGS: u64 = std::mem::offset_of!(Counters, update_args) as u64;
    pub const DRAW_ARGS: u64 = std::mem::offset_of!(Counters, draw_args) as u64;

    /// Particles that left the system: every death and type change.
    pub fn deaths(&self) -> u64 {
        [
            self.died_life,
            self.died_view,
            self.died_distance,
            self.died_collision,
            self.changed,
        ]
        .iter()
        .map(|&d| d as u64)
        .sum()
    }
}

fn v3(a: [f32; 3], w: f32) -> V4 {
    [a[0], a[1], a[2], w]
}

impl SystemParams {
    /// The block for `spec` (validated); `type_id` tells systems apart in the shaders.
    /// Long because it fills the GPU block field by field, in the block's order.
    pub fn new(spec: &SystemSpec, type_id: u32) -> Self {
        let mut p = Self::zeroed();
        let e = &spec.emitter;
        let shape = match e.shape {
            Shape::Point => codes::E_POINT,
            Shape::Box => codes::E_BOX,
            Shape::Sphere => codes::E_SPHERE,
            Shape::Disc => codes::E_DISC,
            Shape::Mesh => codes::E_MESH,
        } as f32;
        p.emitter = v3(e.centre, shape);
        p.extent = match e.shape {
            Shape::Box => v3(e.half, e.surface as u32 as f32),
            _ => [e.radius, e.radius, e.radius, e.surface as u32 as f32],
        };
        p.normal = v3(e.normal, 0.0);
        let q = &spec.particle;
        p.offset_mean = v3(q.offset.mean, 0.0);
        p.offset_var = v3(q.offset.variance, 0.0);
        p.vel_mean = v3(q.velocity.mean, q.spread.to_radians());
        p.vel_var = v3(q.velocity.variance, 0.0);
        p.color_mean = q.color.mean;
        p.color_var = q.color.variance;
        p.scalar_mean = [q.size.mean, q.life.mean, 0.0, 0.0];
        p.scalar_var = [q.size.variance, q.life.variance, 0.0, 0.0];
        p.gravity = v3(spec.gravity, 0.0);
        p.wind = spec.wind;
        p.death = [
            spec.damping,
            spec.death.max_distance.unwrap_or(0.0),
            spec.death.out_of_view as u32 as f32,
            type_id as f32,
        ];
        let o = &spec.over_life;
        p.counts = [
            spec.force.len() as u32,
            spec.collider.len() as u32,
            o.size.len() as u32,
            o.color.len() as u32,
        ];
        let integrator = match spec.integrator() {
            Integrator::Euler => codes::I_EULER,
            Integrator::Verlet => codes::I_VERLET,
            Integrator::Closed => codes::I_CLOSED,
        };
        let mut events = 0;
        for e in &spec.event {
            events |= match (e.on, e.keep_parent) {
                (EventKind::Collision, false) => EV_COLLISION,
                (EventKind::Collision, true) => EV_COLLISION | EV_KEEP_PARENT,
                (EventKind::Death, _) => EV_DEATH,
            };
        }
        p.counts2 = [o.opacity.len() as u32, integrator, events, 0];
        for (k, s) in o.size.iter().enumerate() {
            p.size_keys[k] = [s[0], s[1], 0.0, 0.0];
        }
        for (k, c) in o.color.iter().enumerate() {
            p.color_keys[k] = [c[1], c[2], c[3], c[0]];
        }
        for (k, s) in o.opacity.iter().enumerate() {
            p.opacity_keys[k] = [s[0], s[1], 0.0, 0.0];
        }
        let code = |c: u32| c as f32;
        for (k, f) in spec.force.iter().enumerate() {
            p.forces[k] = match f.kind {
                ForceKind::Attractor => [
                    v3(f.at, code(codes::F_ATTRACTOR)),
                    [f.strength, f.eps, 0.0, 0.0],
                ],
                ForceKind::Vortex => [v3(f.at, code(codes::F_VORTEX)), v3(f.axis, f.strength)],
                ForceKind::Curl => [
                    v3([0.0; 3], code(codes::F_CURL)),
                    [f.strength, f.scale, f.speed, 0.0],
                ],
            };
        }
        for (k, c) in spec.collider.iter().enumerate() {
            let resp = [
                c.restitution,
                c.friction,
                c.inside as u32 as f32,
                c.kill as u32 as f32,
            ];
            p.colliders[k] = match c.kind {
                ColliderKind::Plane => [
                    v3(c.normal, code(codes::C_PLANE)),
                    [c.offset, 0.0, 0.0, 0.0],
                    resp,
                ],
                ColliderKind::Sphere => [
                    v3(c.centre, code(codes::C_SPHERE)),
                    [c.radius, 0.0, 0.0, 0.0],
                    resp,
                ],
                ColliderKind::Box => [v3(c.min, code(codes::C_BOX)), v3(c.max, 0.0), resp],
                ColliderKind::Capsule => [v3(c.a, code(codes::C_CAPSULE)), v3(c.b, c.radius), resp],
                ColliderKind::Character => [v3([0.0; 3], code(codes::C_CHARACTER)), [0.0; 4], resp],
            };
        }
        if let Some(b) = &spec.boids {
            let g = b.grid();
            p.boids = [
                [b.radius, b.separation_radius, b.max_speed, b.max_steer],
                [b.separation, b.alignment, b.cohesion, b.avoidance],
                v3(g.origin, g.cell),
                [b.look_ahead, b.min_speed, 0.0, 0.0],
            ];
            p.grid_dims = [g.dims[0], g.dims[1], g.dims[2], 1];
        }
        p
    }
}

impl BoidsSpec {
    /// The neighbour grid: cells of the perception radius over the bounds (validated).
    pub fn grid(&self) -> GridSpec {
        GridSpec::covering(self.bounds[0], self.bounds[1], self.radius)
            .expect("validated boids bounds")
    }
}

pub use super::codes::{EV_COLLISION, EV_DEATH, EV_KEEP_PARENT};

/// The header of an event list (`Events` in glsl/psys/state.glsl): the count, then the
/// spawn's indirect dispatch; the records follow.
pub const EVENTS_HEADER: u64 = 16;
pub const EVENTS_ARGS: u64 = 4;
/// Bytes of one event record: position (w kind), velocity, contact normal.
pub const EVENT_BYTES: u64 = 48;

/// Per-frame push constants of the compute passes (`Push` in glsl/psys/state.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct StepPush {
    pub view_proj: [[f32; 4]; 4],
    pub source: V4,
    pub births: u32,
    pub seed: u32,
    pub cur: u32,
    pub head: u32,
    pub dt: f32,
    pub capacity: u32,
    pub mode: u32,
    pub cells: u32,
    pub near: f32,
    pub far: f32,
    /// The scene character's capsules and triangles (0 without one).
    pub capsules: u32,
    pub triangles: u32,
}
const _: () = assert!(std::mem::size_of::<StepPush>() == 128);

/// Push constants of the draw (`Push` in glsl/psys/draw.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DrawPush {
    pub view_proj: [[f32; 4]; 4],
    pub right: V4,
    pub up: V4,
    pub screen: V4,
    pub offset: u32,
    pub identity: u32,
    pub pad: [u32; 2],
}
const _: () = assert!(std::mem::size_of::<DrawPush>() == 128);

crate::gpu_interface! {
    /// glsl/psys/emit.comp, args.comp, update.comp, keys.comp (glsl/psys/state.glsl)
    pub PsysIo / PsysBufs: "PSYS", push StepPush {
        params = 0, counters = 1, dead = 2, alive = 3, pos = 4, vel = 5, prev = 6, color = 7,
        keys = 8, vals = 9, events = 10, steer = 11, capsules = 12, mesh_pos = 13,
        mesh_idx = 14, mesh_cdf = 15,
    }
}

crate::gpu_interface! {
    /// glsl/psys/boids.comp (the nb_* bindings are the neighbour grid's cells)
    pub BoidsIo / BoidsBufs: "BOIDS", push StepPush {
        params = 0, counters = 1, alive = 2, pos = 3, vel = 4, steer = 5, perm = 6,
        nb_keys = 7, nb_start = 8, nb_end = 9, nb_box = 10, capsules = 11,
    }
}

crate::gpu_interface! {
    /// glsl/psys/draw.vert, draw.frag (glsl/psys/draw.glsl)
    pub DrawIo / DrawBufs: "PDRAW", push DrawPush {
        params = 0, pos = 1, vel = 2, prev = 3, color = 4, order = 5, sprite = 6,
    }
}

/// The draw mode's shader define and primitive topology.
/// Whether the update aggregates its list appends per subgroup (ballot).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ballot(pub bool);

impl PassKey for Ballot {
    fn all() -> Vec<Self> {
        vec![Self(false), Self(true)]
    }
    fn defines(&self) -> Defines {
        let d = Passes::update_defines(self.0).into_iter();
        d.map(|(k, v)| (k.to_string(), v)).collect()
    }
}

/// The boids' neighbour search: the counting grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoidsGrid(pub NbKey);

impl PassKey for BoidsGrid {
    fn all() -> Vec<Self> {
        vec![Self(NbKey {
            strategy: Neighbors::Grid,
            sort: SortAlgo::Counting,
        })]
    }
    fn defines(&self) -> Defines {
        self.0.defines()
    }
}

impl PassKey for SpriteMode {
    fn all() -> Vec<Self> {
        SpriteMode::all().to_vec()
    }
    fn defines(&self) -> Defines {
        vec![("MODE".to_string(), draw_mode(*self).0.to_string())]
    }
}

crate::gpu::compute_pass!(pub EMIT: PsysIo, () = "psys emit", "psys/emit.comp");
crate::gpu::compute_pass!(pub ARGS: PsysIo, () = "psys args", "psys/args.comp");
crate::gpu::compute_pass!(pub UPDATE: PsysIo, Ballot = "psys update", "psys/update.comp");
crate::gpu::compute_pass!(pub KEYS: PsysIo, () = "psys keys", "psys/keys.comp");
crate::gpu::compute_pass!(pub BOIDS: BoidsIo, BoidsGrid = "psys boids", "psys/boids.comp");
crate::gpu::graphics_pass!(pub DRAW: DrawIo, SpriteMode = "psys draw", "psys/draw.vert", "psys/draw.frag");

pub fn draw_mode(mode: SpriteMode) -> (u32, vk::PrimitiveTopology, bool) {
    match mode {
        SpriteMode::Points => (0, vk::PrimitiveTopology::POINT_LIST, false),
        SpriteMode::Streaks => (1, vk::PrimitiveTopology::LINE_LIST, true),
        SpriteMode::Sprites => (2, vk::PrimitiveTopology::TRIANGLE_LIST, true),
    }
}

/// Vertices per particle of a draw mode.
pub fn vertices(mode: SpriteMode) -> u32 {
    match mode {
        SpriteMode::Points => 1,
        SpriteMode::Streaks => 2,
        SpriteMode::Sprites => 6,
    }
}

/// The pipelines every particle system uses (one set per context).
pub struct Passes {
    pub emit: ComputePipeline<PsysIo>,
    pub args: ComputePipeline<PsysIo>,
    pub update: ComputePipeline<PsysIo>,
    pub keys: ComputePipeline<PsysIo>,
    pub boids: ComputePipeline<BoidsIo>,
    /// The boids' neighbour grid (counting sort).
    pub grid: NeighborSearch,
    /// Points, streaks, sprites.
    pub draw: Vec<GraphicsPipeline<DrawIo>>,
    pub odd_even: NetworkSort,
    pub bitonic: NetworkSort,
    pub counting: CountingSort,
    pub scan: ScanPass,
    /// Bound where a system has no scene character (16 bytes).
    pub dummy: Buffer,
}

impl Passes {
    pub const EMIT: ScopeName = ScopeName::new("emit");
    pub const UPDATE: ScopeName = ScopeName::new("update");
    pub const EVENTS: ScopeName = ScopeName::new("events");
    pub const BOIDS: ScopeName = ScopeName::new("boids");
    pub const SORT: ScopeName = ScopeName::new("sort");
    pub const DRAW: ScopeName = ScopeName::new("draw");

    pub fn new(ctx: &Context) -> Result<Self> {
        Self::with_subgroups(ctx, ctx.info.subgroup_arithmetic)
    }

    /// `subgroups`: aggregate the update's list appends per subgroup (the device must
    /// have subgroup ballot); off, one atomic per particle (the plain variant).
    pub fn with_subgroups(ctx: &Context, subgroups: bool) -> Result<Self> {
        let emit = Guard::new(ctx, EMIT.pipeline(ctx, &(), 256, &[])?);
        let args = Guard::new(ctx, ARGS.pipeline(ctx, &(), 1, &[])?);
        let update = Guard::new(ctx, UPDATE.pipeline(ctx, &Ballot(subgroups), 256, &[])?);
        let keys = Guard::new(ctx, KEYS.pipeline(ctx, &(), 256, &[])?);
        let grid = Guard::new(
            ctx,
            NeighborSearch::new(ctx, Neighbors::Grid, Some(SortAlgo::Counting))?,
        );
        let boids = Guard::new(ctx, BOIDS.pipeline(ctx, &BoidsGrid(grid.key()), 256, &[])?);
        let mut draw = Guard::new(ctx, Vec::new());
        for mode in [SpriteMode::Points, SpriteMode::Streaks, SpriteMode::Sprites] {
            let (_, topology, blend) = draw_mode(mode);
            let states = GraphicsStates {
                color_format: Some(COLOR_FORMAT),
                depth_format: Some(DEPTH_FORMAT),
                blend,
                topology,
            };
            draw.push(DRAW.pipeline(ctx, &mode, states)?);
        }
        let odd_even = Guard::new(ctx, NetworkSort::new(ctx, Network::OddEven)?);
        let bitonic = Guard::new(ctx, NetworkSort::new(ctx, Network::Bitonic)?);
        let counting = Guard::new(ctx, CountingSort::new(ctx)?);
        let scan = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
        let dummy = ctx.storage_buffer("psys no character", 16)?;
        Ok(Self {
            odd_even: odd_even.take(),
            bitonic: bitonic.take(),
            counting: counting.take(),
            scan: scan.take(),
            dummy,
            emit: emit.take(),
            args: args.take(),
            update: update.take(),
            keys: keys.take(),
            boids: boids.take(),
            grid: grid.take(),
            draw: draw.take(),
        })
    }

    /// SUBGROUP: appends to the lists aggregated per subgroup (ballot).
    pub fn update_defines(subgroups: bool) -> Vec<(&'static str, String)> {
        match subgroups {
            true => vec![("SUBGROUP", "1".into())],
            false => vec![],
        }
    }

    pub fn pipeline(&self, mode: SpriteMode) -> &GraphicsPipeline<DrawIo> {
        &self.draw[draw_mode(mode).0 as usize]
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.emit.destroy(ctx);
        self.args.destroy(ctx);
        self.update.destroy(ctx);
        self.keys.destroy(ctx);
        self.boids.destroy(ctx);
        self.grid.destroy(ctx);
        for d in &mut self.draw {
            d.destroy(ctx);
        }
        self.odd_even.destroy(ctx);
        self.bitonic.destroy(ctx);
        self.counting.destroy(ctx);
        self.scan.destroy(ctx);
        ctx.destroy_buffer(&mut self.dummy);
    }
}
crate::impl_destroy!(Passes);
