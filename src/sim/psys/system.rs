//! One particle system's sized part: its slots, alive and dead lists, counters, sort
//! buffers and sprite texture, and how a frame is recorded: emit, update (indirect over
//! the alive list), sort by view depth, draw (indirect). The CPU draws only the number of
//! births per frame; nothing is read back per frame.
use super::character::CharacterBufs;
use super::gpu::{
    vertices, BoidsBufs, Counters, DrawBufs, DrawPush, Passes, PsysBufs, StepPush, SystemParams,
    EVENTS_ARGS, EVENTS_HEADER, EVENT_BYTES,
};
use super::spec::{EventKind, EventSpec};
use super::spec::{Shape, SystemSpec};
use super::sprite;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, Context, Guard, Scopes};
use crate::kinds::SortAlgo;
use crate::primitives::counting::CountingBuffers;
use crate::primitives::neighbors::NeighborBuffers;
use crate::psys::{Integrator, SpriteMode};
use crate::render::Camera;
use bytemuck::Zeroable;
use rand::{Rng, SeedableRng};

mod draw;
use draw::DepthSort;

/// Cells of the counting sort of sprite depths: log-scale depth buckets between the
/// camera's near and far planes (relative depth resolution ln(far / near) / cells).
pub const DEPTH_CELLS: u32 = 1 << 18;

/// The frame a system steps to and is drawn in.
#[derive(Clone, Copy)]
pub struct FrameInfo<'a> {
    pub cam: &'a Camera,
    /// Scene time at the start of the frame (s).
    pub time: f64,
    pub dt: f32,
    pub frame: u64,
    pub width: u32,
    pub height: u32,
    /// The scene character (mesh emitters, character colliders).
    pub character: Option<CharacterBufs<'a>>,
}

/// The state read back (tests, summaries).
pub struct StateDump {
    pub counters: Counters,
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    /// The alive list the last step wrote.
    pub alive: Vec<u32>,
    /// Free slots (euler, verlet).
    pub dead: Vec<u32>,
}

pub struct ParticleSystem {
    pub spec: SystemSpec,
    pub capacity: u32,
    pub sort: SortAlgo,
    pub mode: SpriteMode,
    params: Buffer,
    pub counters: Buffer,
    dead: Buffer,
    alive: Buffer,
    pos: Buffer,
    vel: Buffer,
    prev: Buffer,
    color: Buffer,
    keys: Buffer,
    vals: Buffer,
    /// Events the update records (header + records; one record when it has none).
    events: Buffer,
    /// Boids: each slot's steering (one entry without boids) and the neighbour grid.
    steer: Buffer,
    flock: Option<NeighborBuffers>,
    counting: Option<DepthSort>,
    sprite: Buffer,
    sprite_side: u32,
    /// The alive list the last step wrote (the one drawn).
    drawn: u32,
    /// Closed form: the ring's next slot.
    head: u32,
    rng: rand_pcg::Pcg32,
    seed: u64,
    /// Closed form: births past the capacity in one frame, refused on the CPU.
    pub refused_cpu: u64,
    /// Sum and sum of squares of the births drawn per frame by the rate.
    pub births_sum: (f64, f64),
    /// Births of the first frame's burst.
    burst: u64,
    pub frames: u64,
    /// Scene time after the last recorded step (s).
    last_time: f64,
}

impl StateDump {
    /// Closed form: the slots born within their life at time `t` (what is drawn).
    pub fn live_closed(&self, t: f64) -> Vec<u32> {
        (0..self.pos.len() as u32)
            .filter(|&i| {
                let (p, v) = (self.pos[i as usize], self.vel[i as usize]);
                p[3] >= 0.0 && t - (p[3] as f64) < v[3] as f64
            })
            .collect()
    }
}

/// The device draws the system's points and holds its buffers.
fn check_fits(ctx: &Context, spec: &SystemSpec) -> Result<()> {
    let max_px = ctx.info.max_point_size;
    if spec.draw() == SpriteMode::Points && spec.point_px > max_px {
        return Err(Error::Unsupported(format!(
            "system '{}': points of {} px, but the device draws points of at most {max_px} px",
            spec.name, spec.point_px
        )));
    }
    let cap = spec.capacity as u64;
    let bytes = cap * 16;
    let need = bytes * 4
        + cap * 4 * 5
        + cap * spec.event.len() as u64 * EVENT_BYTES
        + if spec.sort() == SortAlgo::Counting {
            cap * 12 + DEPTH_CELLS as u64 * 12
        } else {
            0
        }
        // Boids: steering, and the grid's keys, permutation, sorted positions, one
        // neighbour count and list entry per slot, counting-sort scratch and cell ranges.
        + match &spec.boids {
            Some(b) => cap * 68 + (b.grid().cells() + 1) * 12,
            None => 0,
        };
    if need > ctx.info.device_local_bytes {
        return Err(Error::Param(format!(
            "system '{}': {} slots need {} MB, more than the device's {} MB",
            spec.name,
            cap,
            need >> 20,
            ctx.info.device_local_bytes >> 20
        )));
    }
    Ok(())
}

impl ParticleSystem {
    /// Slots for `spec` (validated by the caller), every slot free. Long because every
    /// buffer is made under its own guard and moved into the system at the end (a failure
    /// part-way frees what was made), then given its first contents.
    pub fn new(
        ctx: &Context,
        passes: &Passes,
        spec: &SystemSpec,
        type_id: u32,
        seed: u64,
    ) -> Result<Self> {
        spec.validate()?;
        check_fits(ctx, spec)?;
        let cap = spec.capacity as u64;
        let bytes = cap * 16;
        let name = &spec.name;
        let buf = |what: &str, size: u64| {
            ctx.storage_buffer(&format!("{name} {what}"), size)
                .map(|b| Guard::new(ctx, b))
        };
        let mut params = buf("params", std::mem::size_of::<SystemParams>() as u64)?;
        let mut counters = Guard::new(
            ctx,
            ctx.indirect_buffer(
                &format!("{name} counters"),
                std::mem::size_of::<Counters>() as u64,
            )?,
        );
        let mut dead = buf("dead list", cap * 4)?;
        let alive = buf("alive lists", cap * 8)?;
        let mut pos = buf("positions", bytes)?;
        let vel = buf("velocities", bytes)?;
        let prev = buf("previous positions", bytes)?;
        let color = buf("colours", bytes)?;
        let records = (cap * spec.event.len() as u64).max(1);
        let events = Guard::new(
            ctx,
            ctx.indirect_buffer(
                &format!("{name} events"),
                EVENTS_HEADER + records * EVENT_BYTES,
            )?,
        );
        let steer = buf("steering", if spec.boids.is_some() { cap * 16 } else { 16 })?;
        let flock = Guard::new(
            ctx,
            match &spec.boids {
                Some(b) => Some(passes.grid.buffers(ctx, cap, &b.grid(), 1)?),
                None => None,
            },
        );
        let keys = buf("sort keys", cap * 4)?;
        let vals = buf("sort values", cap * 4)?;
        let counting = Guard::new(
            ctx,
            match spec.sort() {
                SortAlgo::Counting => Some(DepthSort::new(ctx, passes, name, cap)?),
                _ => None,
            },
        );
        let (side, texels) = sprite::texture(
            spec.sprite.unwrap_or(super::spec::SpriteTexture::Disc),
            seed,
        );
        let mut sprite_buf = buf("sprite", texels.len() as u64 * 4)?;
        ctx.upload(&mut sprite_buf, 0, &texels)?;
        ctx.upload(&mut params, 0, &[SystemParams::new(spec, type_id)])?;
        // Every slot free; popped from the end, so low slots are used first.
        let free: Vec<u32> = (0..spec.capacity).rev().collect();
        ctx.upload(&mut dead, 0, &free)?;
        let c = Counters {
            dead_count: spec.capacity as i32,
            verts: vertices(spec.draw()),
            draw_args: [0, 1, 0, 0],
            ..Counters::zeroed()
        };
        ctx.upload(&mut counters, 0, &[c])?;
        // w = -1 marks a slot never born: closed form's birth time; stateful systems read
        // slots via lists, but the boids' grid sorts every slot and skips these.
        if spec.integrator() == Integrator::Closed || spec.boids.is_some() {
            let unborn = vec![[0.0f32, 0.0, 0.0, -1.0]; spec.capacity as usize];
            ctx.upload(&mut pos, 0, &unborn)?;
        }
        Ok(Self {
            spec: spec.clone(),
            capacity: spec.capacity,
            sort: spec.sort(),
            mode: spec.draw(),
            params: params.take(),
            counters: counters.take(),
            dead: dead.take(),
            alive: alive.take(),
            pos: pos.take(),
            vel: vel.take(),
            prev: prev.take(),
            color: color.take(),
            keys: keys.take(),
            vals: vals.take(),
            events: events.take(),
            steer: steer.take(),
            flock: flock.take(),
            counting: counting.take(),
            sprite: sprite_buf.take(),
            sprite_side: side,
            drawn: 0,
            head: 0,
            rng: rand_pcg::Pcg32::seed_from_u64(seed ^ (type_id as u64).wrapping_mul(0x9e37_79b9)),
            seed,
            refused_cpu: 0,
            births_sum: (0.0, 0.0),
            burst: 0,
            frames: 0,
            last_time: 0.0,
        })
    }

    /// The alive list the last step wrote.
    pub fn drawn(&self) -> u32 {
        self.drawn
    }

    /// Scene time after the last recorded step (s).
    pub fn time_now(&self) -> f64 {
        self.last_time
    }

    /// Births drawn on the CPU so far (the rate's and the first frame's burst).
    pub fn births_asked(&self) -> u64 {
        self.births_sum.0 as u64 + self.burst
    }

    /// Boids: each slot's steering acceleration (xyz) and flockmates seen (w) from the
    /// last step (tests).
    pub fn read_steer(&self, ctx: &Context) -> Result<Vec<[f32; 4]>> {
        ctx.readback(&self.steer, 0, self.steer.size as usize / 16)
    }

    /// Drawn as points: opaque and depth-written (the other modes are alpha-blended).
    pub fn opaque(&self) -> bool {
        self.mode == SpriteMode::Points
    }

    pub fn closed(&self) -> bool {
        self.spec.integrator() == Integrator::Closed
    }

    /// The emitter's centre at time `t` (an orbit moves it).
    pub fn source(&self, t: f64) -> glam::Vec3 {
        let e = &self.spec.emitter;
        let c = glam::Vec3::from(e.centre);
        match e.orbit {
            Some([r, period]) => {
                let a = std::f64::consts::TAU * t / period as f64;
                c + glam::Vec3::new(r * a.cos() as f32, 0.0, r * a.sin() as f32)
            }
            None => c,
        }
    }

    /// Radius of the emitter's bounding sphere (per-area emission).
    fn emitter_radius(&self) -> f32 {
        let e = &self.spec.emitter;
        let r = match e.shape {
            Shape::Box => glam::Vec3::from(e.half).length(),
            Shape::Sphere | Shape::Disc => e.radius,
            Shape::Point | Shape::Mesh => 0.0,
        };
        r.max(self.spec.particle.size.mean * 0.5).max(1e-3)
    }

    /// Births this frame: mean + rand x variance (rand in [-1, 1)), or per_area x the
    /// emitter's projected area in pixels; rounded stochastically so the mean is exact.
    pub fn draw_births(&mut self, f: &FrameInfo) -> u32 {
        let e = &self.spec.emitter;
        let x = match (&e.rate, e.per_area) {
            (Some(r), _) => r.mean + self.rng.random_range(-1.0f32..1.0) * r.variance,
            (None, Some(a)) => {
                let d = (self.source(f.time) - f.cam.eye).length().max(f.cam.near);
                let focal = f.height as f32 / (2.0 * (f.cam.fov_y_deg.to_radians() * 0.5).tan());
                let px = self.emitter_radius() * focal / d;
                a * std::f32::consts::PI * px * px
            }
            (None, None) => 0.0,
        };
        let mut n = (x.max(0.0) + self.rng.random_range(0.0f32..1.0)).floor() as u64;
        self.births_sum.0 += n as f64;
        self.births_sum.1 += (n * n) as f64;
        if self.frames == 0 {
            n += e.burst as u64;
            self.burst = e.burst as u64;
        }
        let cap = if self.closed() {
            self.capacity as u64
        } else {
            u32::MAX as u64
        };
        if n > cap {
            self.refused_cpu += n - cap;
        }
        n.min(cap) as u32
    }

    /// The system's buffers, with the frame's character (or the stand-in).
    fn bufs<'a>(&'a self, passes: &'a Passes, f: &FrameInfo<'a>) -> PsysBufs<'a> {
        let d = &passes.dummy;
        let ch = f.character;
        PsysBufs {
            params: &self.params,
            counters: &self.counters,
            dead: &self.dead,
            alive: &self.alive,
            pos: &self.pos,
            vel: &self.vel,
            prev: &self.prev,
            color: &self.color,
            keys: &self.keys,
            vals: &self.vals,
            events: &self.events,
            steer: &self.steer,
            capsules: ch.map_or(d, |c| c.capsules),
            mesh_pos: ch.map_or(d, |c| c.pos),
            mesh_idx: ch.map_or(d, |c| c.indices),
            mesh_cdf: ch.map_or(d, |c| c.cdf),
        }
    }

    fn push(&self, f: &FrameInfo, t: f64, births: u32) -> StepPush {
        let s = self.source(f.time);
        StepPush {
            view_proj: f.cam.view_proj().to_cols_array_2d(),
            source: [s.x, s.y, s.z, t as f32],
            births,
            seed: (crate::psys::hash64(self.seed ^ f.frame.wrapping_mul(0x2545_f491)) & 0xffff_ffff)
                as u32,
            cur: self.drawn,
            head: self.head,
            dt: f.dt,
            capacity: self.capacity,
            mode: 0,
            cells: DEPTH_CELLS,
            near: f.cam.near,
            far: f.cam.far,
            capsules: f.character.map_or(0, |c| c.capsule_count),
            triangles: f.character.map_or(0, |c| c.triangles),
        }
    }

    /// Record a frame's births and step (Euler, Verlet) or births only (closed form).
    pub fn record_step(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        passes: &Passes,
        f: &FrameInfo,
    ) {
        let births = self.draw_births(f);
        self.record_births(ctx, cmd, scopes, passes, f, births);
    }

    /// `record_step` with `births` chosen by the caller (tests, a benchmark's prefill).
    pub fn record_births(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        passes: &Passes,
        f: &FrameInfo,
        births: u32,
    ) {
        self.frames += 1;
        self.last_time = f.time + f.dt as f64;
        let push = self.push(f, f.time, births);
        let bufs = self.bufs(passes, f);
        {
            let _scope = scopes.open(ctx, cmd, Passes::EMIT);
            passes.emit.dispatch(ctx, cmd, &bufs, &push, births as u64);
        }
        if self.closed() {
            self.head = ((self.head as u64 + births as u64) % self.capacity as u64) as u32;
            return;
        }
        {
            let mut scopes = scopes.open(ctx, cmd, Passes::UPDATE);
            passes.args.dispatch_groups(ctx, cmd, &bufs, &push, 1);
            if let (Some(nb), Some(b)) = (&self.flock, &self.spec.boids) {
                // The grid over every slot (dead ones sort last), then each boid's steering.
                {
                    let mut scopes = scopes.open(ctx, cmd, Passes::BOIDS);
                    let r = passes.grid.record_build(
                        ctx,
                        cmd,
                        &mut *scopes,
                        nb,
                        &self.pos,
                        self.capacity,
                        &b.grid(),
                    );
                    debug_assert!(r.is_ok(), "the grid was sized for every slot");
                    let (nb_start, nb_end) = nb.cell_buffers();
                    let b = BoidsBufs {
                        params: &self.params,
                        counters: &self.counters,
                        alive: &self.alive,
                        pos: &self.pos,
                        vel: &self.vel,
                        steer: &self.steer,
                        perm: &nb.perm,
                        nb_keys: &nb.sorted_keys,
                        nb_start,
                        nb_end,
                        nb_box: nb.box_buffer(),
                        capsules: bufs.capsules,
                    };
                    passes.boids.dispatch_indirect(
                        ctx,
                        cmd,
                        &b,
                        &push,
                        &self.counters,
                        Counters::UPDATE_ARGS,
                    );
                }
            }
            passes.update.dispatch_indirect(
                ctx,
                cmd,
                &bufs,
                &push,
                &self.counters,
                Counters::UPDATE_ARGS,
            );
            self.drawn = 1 - self.drawn;
            self.record_draw_count(ctx, cmd, passes, f);
        }
    }

    /// Record the spawn's indirect dispatch over the events this frame's step recorded
    /// (after the step's writes are visible).
    pub fn record_event_args(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        passes: &Passes,
        f: &FrameInfo,
    ) {
        let push = StepPush {
            mode: 3,
            ..self.push(f, f.time, 0)
        };
        passes
            .args
            .dispatch_groups(ctx, cmd, &self.bufs(passes, f), &push, 1);
    }

    /// Record the children of `parent`'s events of `event`'s kind, born into this system's
    /// list that is drawn (after `record_event_args` of the parent, visible to indirect
    /// reads). `record_draw_count` afterwards counts them into the draw.
    pub fn record_spawn(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        passes: &Passes,
        f: &FrameInfo,
        parent: &ParticleSystem,
        event: &EventSpec,
    ) {
        let kind = match event.on {
            EventKind::Collision => 1,
            EventKind::Death => 2,
        };
        let mut push = self.push(f, f.time, event.along_normal as u32);
        push.source = [event.count.mean, event.count.variance, event.inherit, 0.0];
        push.mode = kind;
        push.seed ^= (crate::psys::hash64(parent.seed ^ kind as u64) & 0xffff_ffff) as u32;
        let bufs = PsysBufs {
            events: &parent.events,
            ..self.bufs(passes, f)
        };
        passes
            .emit
            .dispatch_indirect(ctx, cmd, &bufs, &push, &parent.events, EVENTS_ARGS);
    }

    /// Colours at birth (tests identify particles by them).
    pub fn color_buffer(&self) -> &Buffer {
        &self.color
    }

    pub fn read_counters(&self, ctx: &Context) -> Result<Counters> {
        Ok(ctx.readback::<Counters>(&self.counters, 0, 1)?[0])
    }

    /// The state after the last submitted frame (waits for nothing: call after it).
    pub fn read(&self, ctx: &Context) -> Result<StateDump> {
        let counters = self.read_counters(ctx)?;
        let cap = self.capacity as usize;
        let all: Vec<u32> = ctx.readback(&self.alive, 0, 2 * cap)?;
        let n_alive = counters.alive[self.drawn as usize] as usize;
        let start = self.drawn as usize * cap;
        let dead_n = counters.dead_count.max(0) as usize;
        Ok(StateDump {
            pos: ctx.readback(&self.pos, 0, cap)?,
            vel: ctx.readback(&self.vel, 0, cap)?,
            alive: all[start..start + n_alive.min(cap)].to_vec(),
            dead: ctx.readback(&self.dead, 0, cap)?[..dead_n.min(cap)].to_vec(),
            counters,
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.params,
            &mut self.counters,
            &mut self.dead,
            &mut self.alive,
            &mut self.pos,
            &mut self.vel,
            &mut self.prev,
            &mut self.color,
            &mut self.keys,
            &mut self.vals,
            &mut self.events,
            &mut self.steer,
            &mut self.sprite,
        ] {
            ctx.destroy_buffer(b);
        }
        if let Some(nb) = &mut self.flock {
            nb.destroy(ctx);
        }
        if let Some(d) = &mut self.counting {
            d.destroy(ctx);
        }
    }
}

crate::impl_destroy!(ParticleSystem);
