//! The `orbits` test scene's simulation: particles orbiting an attractor inside a box,
//! moved by one compute pass (its scene is made in code, `fluidform run --scene orbits`).
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard};
use bytemuck::{Pod, Zeroable};
use rand::{Rng, SeedableRng};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct OrbitsPush {
    pub dt: f32,
    pub strength: f32,
    pub eps: f32,
    pub n: u32,
}
const _: () = assert!(std::mem::size_of::<OrbitsPush>() == 16);

/// Initial state: positions (xyz, radius), velocities, colours; deterministic in `seed`.
pub struct OrbitsState {
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    pub color: Vec<[f32; 4]>,
}

pub const STRENGTH: f32 = 0.5;
pub const EPS: f32 = 0.01;
pub const RADIUS: f32 = 0.02;

pub fn initial_state(n: usize, seed: u64) -> OrbitsState {
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut s = OrbitsState {
        pos: Vec::with_capacity(n),
        vel: Vec::with_capacity(n),
        color: Vec::with_capacity(n),
    };
    for _ in 0..n {
        let r: f32 = rng.random_range(0.3..0.9);
        let dir = loop {
            let d = glam::Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if d.length_squared() > 1e-3 && d.length_squared() <= 1.0 {
                break d.normalize();
            }
        };
        let p = dir * r;
        // Circular speed for force strength / (r^2 + eps), about a random axis.
        let axis = glam::Vec3::new(0.2, 1.0, 0.1).normalize();
        let t = axis.cross(dir).try_normalize().unwrap_or(glam::Vec3::X);
        let v = t * (STRENGTH * r / (r * r + EPS)).sqrt() * rng.random_range(0.8..1.1);
        let c = (r - 0.3) / 0.6;
        s.pos.push([p.x, p.y, p.z, RADIUS]);
        s.vel.push([v.x, v.y, v.z, 0.0]);
        s.color.push([0.2 + 0.8 * c, 0.5, 1.0 - 0.8 * c, 1.0]);
    }
    s
}

/// CPU reference of one step (the same f32 arithmetic as glsl/orbits/orbits.comp).
pub fn step_cpu(pos: &mut [[f32; 4]], vel: &mut [[f32; 4]], push: &OrbitsPush) {
    for (p4, v4) in pos.iter_mut().zip(vel.iter_mut()) {
        let mut p = glam::Vec3::from_slice(&p4[..3]);
        let mut v = glam::Vec3::from_slice(&v4[..3]);
        let r2 = p.dot(p);
        v += -p / (r2 + push.eps).sqrt() * (push.strength / (r2 + push.eps)) * push.dt;
        p += v * push.dt;
        for k in 0..3 {
            if p[k] > 1.0 {
                p[k] = 2.0 - p[k];
                v[k] = -v[k];
            }
            if p[k] < -1.0 {
                p[k] = -2.0 - p[k];
                v[k] = -v[k];
            }
        }
        p4[..3].copy_from_slice(&p.to_array());
        v4[..3].copy_from_slice(&v.to_array());
    }
}

crate::gpu_interface! {
    /// glsl/orbits/orbits.comp
    pub OrbitsIo / OrbitsBufs: "ORB", push OrbitsPush { pos = 0, vel = 1 }
}

crate::gpu::compute_pass!(pub SIMULATE: OrbitsIo, () = "simulate", "orbits/orbits.comp");

/// The size-independent part: the step pipeline.
pub struct OrbitsPass {
    pipeline: ComputePipeline<OrbitsIo>,
}

impl OrbitsPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Self {
            pipeline: SIMULATE.pipeline(ctx, &(), 256, &[])?,
        })
    }

    pub fn step(&self, ctx: &Context, cmd: vk::CommandBuffer, s: &Orbits, dt: f32) {
        let push = OrbitsPush {
            dt,
            strength: STRENGTH,
            eps: EPS,
            n: s.n,
        };
        let bufs = OrbitsBufs {
            pos: &s.pos,
            vel: &s.vel,
        };
        self.pipeline.dispatch(ctx, cmd, &bufs, &push, s.n as u64);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}

/// The sized part: particle buffers.
pub struct Orbits {
    pub pos: Buffer,
    pub vel: Buffer,
    pub color: Buffer,
    pub n: u32,
}

impl Orbits {
    pub fn new(ctx: &Context, state: &OrbitsState) -> Result<Self> {
        let n = state.pos.len();
        let bytes = (n * 16) as u64;
        let mut bufs = Guard::new(ctx, Vec::new());
        for (name, data) in [
            ("particle positions", &state.pos),
            ("particle velocities", &state.vel),
            ("particle colours", &state.color),
        ] {
            let mut b = ctx.storage_buffer(name, bytes)?;
            let r = ctx.upload(&mut b, 0, data);
            bufs.push(b);
            r?;
        }
        let mut v = bufs.take().into_iter();
        let mut next = || v.next().expect("three buffers");
        Ok(Self {
            pos: next(),
            vel: next(),
            color: next(),
            n: n as u32,
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_buffer(&mut self.pos);
        ctx.destroy_buffer(&mut self.vel);
        ctx.destroy_buffer(&mut self.color);
    }
}
crate::impl_destroy!(OrbitsPass, Orbits);
