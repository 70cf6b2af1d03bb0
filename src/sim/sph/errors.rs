//! The density error of every step, reduced on the GPU (no read-back per step) into a
//! per-frame record list read after the frame's fence: per live particle
//! e = max(rho / rho0 - 1, 0) (compression only: surface particles lack neighbours), its
//! mean and maximum. Reported per step in `steps.csv` and summed up in `summary.json`.
use super::solver::SphState;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard, MemoryLocation};
use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

const WG: u32 = 256;
const ITEMS: u32 = 8;
const BLOCK: u64 = (WG * ITEMS) as u64;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct StepErrorPush {
    pub n: u32,
    pub mode: u32,
    pub step: u32,
    pub rest_density: f32,
}

crate::gpu_interface! {
    /// glsl/sph/step_error.comp
    pub StepErrorIo / StepErrorBufs: "SERR", push StepErrorPush {
        pos = 0, rho_p = 1, partials = 2, records = 3, solve = 4, params = 5,
    }
}

/// The top bit of a solve's iteration count (glsl/sph/pressure.glsl): the solve stopped.
const STOPPED: u32 = 1 << 31;

/// One step's density error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepError {
    pub dt: f32,
    pub mean: f32,
    pub max: f32,
    /// Live particles counted.
    pub particles: u32,
    /// Iterations of the pressure solve (0 for wcsph) and of DFSPH's divergence solve.
    pub iterations: u32,
    pub divergence_iterations: u32,
    /// Whether each solve (density, divergence) stopped by its own rule (its target, or
    /// max_iterations) rather than running out of the iterations its frame recorded.
    pub stopped: [bool; 2],
    /// DFSPH: the divergence solve's mean compression rate times dt at its end.
    pub divergence_error: f32,
    /// The pressure solve's own estimate of the mean density error at its last iteration.
    pub solver_error: f32,
}

/// Density error over a run's steps (`stats.density_error` in summary.json).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct DensityErrorStats {
    pub steps: u64,
    /// Mean over steps of each step's mean error.
    pub mean: f64,
    /// Largest error of any particle in any step.
    pub max: f64,
    /// The last step's mean and maximum.
    pub last_mean: f64,
    pub last_max: f64,
    /// Pressure-solve iterations per step: mean and most (0 for wcsph).
    #[serde(default)]
    pub iterations_mean: f64,
    #[serde(default)]
    pub iterations_max: u32,
    /// DFSPH's divergence solve: iterations per step, and its error (mean compression rate
    /// times dt) averaged over steps.
    #[serde(default)]
    pub divergence_iterations_mean: f64,
    #[serde(default)]
    pub divergence_error_mean: f64,
    /// Solves that ran out of the iterations their frame recorded, fewer than
    /// max_iterations, before they stopped: they ended above their target (see
    /// `Stepper::retire_slot`).
    #[serde(default)]
    pub bounded_steps: u64,
    /// DFSPH: particle-steps with more neighbours than `fluid.neighbor_list`, searched in
    /// the grid instead (exact, slower).
    #[serde(default)]
    pub list_overflows: u64,
}

impl DensityErrorStats {
    pub fn add(&mut self, e: &StepError) {
        let k = self.steps as f64;
        let avg = |m: f64, x: f64| (m * k + x) / (k + 1.0);
        self.mean = avg(self.mean, e.mean as f64);
        self.max = self.max.max(e.max as f64);
        self.last_mean = e.mean as f64;
        self.last_max = e.max as f64;
        self.iterations_mean = avg(self.iterations_mean, e.iterations as f64);
        self.iterations_max = self.iterations_max.max(e.iterations);
        self.divergence_iterations_mean = avg(
            self.divergence_iterations_mean,
            e.divergence_iterations as f64,
        );
        self.divergence_error_mean = avg(self.divergence_error_mean, e.divergence_error as f64);
        self.steps += 1;
    }
}

pub struct StepErrors {
    pipeline: ComputePipeline<StepErrorIo>,
    partials: Buffer,
    /// Bound as the solve state for wcsph (no pressure solve: zero iterations).
    no_solve: Buffer,
    /// Per slot: two vec4 records per step of the frame, host-visible.
    records: Vec<Buffer>,
    capacity: u64,
    max_steps: u32,
}

crate::gpu::compute_pass!(pub STEP_ERROR: StepErrorIo, () = "sph/errors", "sph/step_error.comp");

impl StepErrors {
    pub const NAME: crate::gpu::ScopeName = STEP_ERROR.scope();

    /// For up to `capacity` particles and `max_steps` steps per frame in each of `slots`.
    pub fn new(ctx: &Context, capacity: u64, slots: usize, max_steps: u32) -> Result<Self> {
        let pipeline = Guard::new(ctx, STEP_ERROR.pipeline(ctx, &(), WG, &[ITEMS])?);
        let partials = Guard::new(
            ctx,
            ctx.storage_buffer("step error partials", capacity.div_ceil(BLOCK).max(1) * 16)?,
        );
        let no_solve = Guard::new(ctx, ctx.storage_buffer("no solve state", 48)?);
        ctx.one_shot(|cmd| ctx.fill(cmd, &no_solve, 0))?;
        let mut records = Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            records.push(ctx.create_buffer(
                "step error records",
                max_steps.max(1) as u64 * 32,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::GpuToCpu,
            )?);
        }
        Ok(Self {
            pipeline: pipeline.take(),
            partials: partials.take(),
            no_solve: no_solve.take(),
            records: records.take(),
            capacity,
            max_steps: max_steps.max(1),
        })
    }

    /// Record the density error of the step just taken (its density pass written and
    /// made visible to compute) as step `step` of the frame in `slot`; the caller makes the
    /// records visible to the host at the frame's end.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        st: &SphState,
        slot: usize,
        step: u32,
    ) -> Result<()> {
        if st.n as u64 > self.capacity || step >= self.max_steps {
            return Err(Error::Param(format!(
                "step errors sized for {} particles and {} steps, asked {} and step {step}",
                self.capacity, self.max_steps, st.n
            )));
        }
        let groups = (st.n as u64).div_ceil(BLOCK).max(1);
        let mut push = StepErrorPush {
            n: st.n,
            mode: 0,
            step,
            rest_density: st.fluid.rest_density,
        };
        let bufs = StepErrorBufs {
            pos: st.pos(),
            rho_p: st.rho_p(),
            partials: &self.partials,
            records: &self.records[slot],
            solve: st.pressure.as_ref().map_or(&self.no_solve, |p| p.solve()),
            params: st.params(),
        };
        self.pipeline
            .dispatch_groups(ctx, cmd, &bufs, &push, groups);
        push.n = groups as u32;
        push.mode = 1;
        self.pipeline.dispatch_groups(ctx, cmd, &bufs, &push, 1);
        Ok(())
    }

    /// At the end of a frame's commands: the records -> the host.
    pub fn record_frame_end(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize) {
        ctx.host_reads(cmd, &[&self.records[slot]]);
    }

    /// After the slot's fence: its frame's first `steps` records.
    pub fn read(&self, slot: usize, steps: u32) -> Vec<StepError> {
        let raw = self.records[slot].mapped().expect("records are mapped");
        let v: &[[[f32; 4]; 2]] =
            bytemuck::cast_slice(&raw[..steps.min(self.max_steps) as usize * 32]);
        v.iter()
            .map(|[r, s]| StepError {
                mean: r[0],
                max: r[1],
                particles: r[2] as u32,
                dt: r[3],
                iterations: s[0].to_bits() & !STOPPED,
                divergence_iterations: s[1].to_bits() & !STOPPED,
                stopped: [s[0].to_bits() & STOPPED != 0, s[1].to_bits() & STOPPED != 0],
                solver_error: s[2],
                divergence_error: s[3],
            })
            .collect()
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        ctx.destroy_buffer(&mut self.partials);
        ctx.destroy_buffer(&mut self.no_solve);
        for b in &mut self.records {
            ctx.destroy_buffer(b);
        }
    }
}

crate::impl_destroy!(StepErrors);
