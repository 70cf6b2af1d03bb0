//! The state's health, read back every frame: particles with a non-finite velocity or
//! density, the largest speed and density. A run stops at the first frame that went
//! unstable, naming the frame and the quantity; CFL steps use the largest speed.
use super::solver::SphState;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard, MemoryLocation};
use bytemuck::{Pod, Zeroable};

/// Mirror of `Health` in glsl/sph/health.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]

pub struct GpuHealth {
    pub nonfinite: u32,
    /// Bits of the largest speed squared.
    pub max_speed2: u32,
    /// Bits of the largest density.
    pub max_density: u32,
    pub pad: u32,
}

impl GpuHealth {
    pub fn max_speed(&self) -> f32 {
        f32::from_bits(self.max_speed2).sqrt()
    }
    pub fn max_density(&self) -> f32 {
        f32::from_bits(self.max_density)
    }
}

crate::gpu_interface! {
    /// glsl/sph/health.comp; push: n.
    pub HealthIo / HealthBufs: "HEALTH", push u32 { vel = 0, rho_p = 1, out = 2 }
}

crate::gpu::compute_pass!(pub HEALTH: HealthIo, () = "health", "sph/health.comp");

/// Densities above this many times rho_0 mean the step cannot resolve the compression.
pub const MAX_DENSITY_RATIO: f32 = 10.0;

pub struct Health {
    pipeline: ComputePipeline<HealthIo>,
    out: Buffer,
    readbacks: Vec<Buffer>,
    /// Per slot: the h / dt of the frame recorded into it.
    limits: Vec<f32>,
    /// Per slot: the CFL number its steps were sized by (None: fixed steps).
    cfls: Vec<Option<f32>>,
}

impl Health {
    pub fn new(ctx: &Context, slots: usize) -> Result<Self> {
        let pipeline = Guard::new(ctx, HEALTH.pipeline(ctx, &(), 128, &[])?);
        let out = Guard::new(ctx, ctx.storage_buffer("sph health", 16)?);
        let mut readbacks = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            readbacks.push(ctx.create_buffer(
                "sph health readback",
                16,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        Ok(Self {
            pipeline: pipeline.take(),
            out: out.take(),
            readbacks: readbacks.take(),
            limits: vec![f32::INFINITY; slots],
            cfls: vec![None; slots],
        })
    }

    /// Record the health of the state after a frame of steps of `dt` into `slot`.
    pub fn record(&mut self, ctx: &Context, cmd: vk::CommandBuffer, st: &SphState, slot: usize) {
        self.limits[slot] = st.fluid.h / st.dt;
        self.cfls[slot] = st.fluid.cfl;
        ctx.fill(cmd, &self.out, 0);
        let bufs = HealthBufs {
            vel: st.vel(),
            rho_p: st.rho_p(),
            out: &self.out,
        };
        self.pipeline.dispatch(ctx, cmd, &bufs, &st.n, st.n as u64);
        ctx.copy(cmd, &self.out, 0, &self.readbacks[slot], 0, 16);
        ctx.host_reads(cmd, &[&self.readbacks[slot]]);
    }

    /// After the slot's fence: the health, or the error of an unstable frame.
    pub fn check(&self, slot: usize, frame: u64, rest_density: f32) -> Result<GpuHealth> {
        let h: GpuHealth =
            bytemuck::pod_read_unaligned(self.readbacks[slot].mapped().expect("mapped"));
        let fix = match self.cfls[slot] {
            Some(c) => format!("lower --fluid cfl (now {c}) or --fluid dt_max"),
            None => "lower --fluid dt or set --fluid cfl=0.4".to_string(),
        };
        if h.nonfinite > 0 {
            return Err(Error::Unstable(format!(
                "frame {frame}: {} particle(s) with a non-finite velocity or density ({fix})",
                h.nonfinite
            )));
        }
        let limit = self.limits[slot];
        if h.max_speed() > limit {
            return Err(Error::Unstable(format!(
                "frame {frame}: a particle at {:.3e} m/s crosses more than the kernel radius \
                 per step (h / dt = {limit:.3e} m/s) ({fix})",
                h.max_speed()
            )));
        }
        if h.max_density() > MAX_DENSITY_RATIO * rest_density {
            return Err(Error::Unstable(format!(
                "frame {frame}: density {:.3e} is {:.0} x rho_0, beyond what the step resolves \
                 ({fix})",
                h.max_density(),
                h.max_density() / rest_density
            )));
        }
        Ok(h)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        ctx.destroy_buffer(&mut self.out);
        for b in &mut self.readbacks {
            ctx.destroy_buffer(b);
        }
    }
}

crate::impl_destroy!(Health);
