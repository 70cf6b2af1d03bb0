//! Playing an SPH scene: steps per frame (fixed, or as many as the GPU's own CFL-limited
//! steps take to cover the frame: sph/cfl.rs), the state's health every frame, and
//! end-of-run statistics.
use super::commands::{CommandStats, StepCommands};
use super::errors::{DensityErrorStats, StepError, StepErrors};
use super::health::Health;
use super::setup::Domain;
use super::solver::{SphSolver, SphState, StateDump};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Context, Profiler};
use crate::sph::Solver;
use serde::{Deserialize, Serialize};

const SPH_HEALTH_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("sph/health");

/// Chooses steps per frame and watches the state's health. With `cfl`, each step's dt is
/// the GPU's, from the step's own velocities (sph/cfl.rs); a frame records as many steps
/// as the last finished frame's last dt takes to cover the frame and the time the
/// simulation trails the frames by (less what the frames in flight already make up): no
/// step is snapped to the frame grid, and leftover time carries into the next frame.
pub struct Stepper {
    health: Health,
    errors: StepErrors,
    /// Per slot: the steps recorded into it and the
    /// iterations each solve recorded (density, divergence; 0: max_iter).
    pending: Vec<(u32, [u32; 2])>,
    /// Per slot: what each of its steps recorded.
    recorded: Vec<Vec<StepCommands>>,
    /// Dispatches, barriers and empty dispatches per step over the finished frames.
    pub commands: CommandStats,
    /// The last frame with a step that used every iteration recorded.
    pub last_bounded_frame: Option<u64>,
    /// Iterations the next frame records per solve (see `retire_slot`).
    bound: [u32; 2],
    /// Per slot: the time its steps were expected to cover beyond the frame (with cfl).
    extra: Vec<f64>,
    /// The last finished step's dt (the GPU's), 0 before any.
    dt_seen: f32,
    /// Simulated time of the finished frames, and their frames' time.
    retired_time: f64,
    retired_frames: u64,
    /// Every step's density error: (frame, step in the frame, time after it, error).
    pub steps: Vec<(u64, u32, f64, StepError)>,
    pub density_error: DensityErrorStats,
    pub frame_time: f64,
    pub steps_taken: u64,
    pub sim_time: f64,
    rest_density: f32,
    /// The fluid's (min, max) iterations.
    iterations: (u32, u32),
    /// Spare iterations recorded: the solver's [`spare_iterations`], raised by each frame
    /// in which a solve ran out.
    spare: u32,
}

/// Iterations a solve records beyond the most any step of the last finished frame used, at
/// first: each costs its passes' empty dispatches per solve and step once the solve has
/// stopped. A frame in which a solve ran out of them raises the run's spare by one (up to
/// [`MOST_SPARE`]). On the dam break at 64K over a second (lavapipe, 2026-11-28), DFSPH
/// ran out of none at 1; PCISPH ran out 10 times at 1 and twice at 2; PBF, whose counts
/// jump from 4 to 48, 19 and 14 times.
pub fn spare_iterations(solver: Solver) -> u32 {
    match solver {
        Solver::Wcsph | Solver::Dfsph => 1,
        Solver::Pcisph | Solver::Pbf => 2,
    }
}

/// The most a run's spare iterations grow to.
pub const MOST_SPARE: u32 = 8;

impl Stepper {
    pub fn new(ctx: &Context, st: &SphState, slots: usize) -> Result<Self> {
        let f = &st.fluid;
        let max_steps = match f.cfl {
            Some(_) => super::params::MAX_SUBSTEPS,
            None => f.substeps,
        };
        let errors =
            crate::gpu::Guard::new(ctx, StepErrors::new(ctx, st.n as u64, slots, max_steps)?);
        Ok(Self {
            health: Health::new(ctx, slots)?,
            errors: errors.take(),
            pending: vec![(0, [0; 2]); slots],
            recorded: vec![Vec::new(); slots],
            commands: CommandStats::default(),
            last_bounded_frame: None,
            bound: [0; 2],
            extra: vec![0.0; slots],
            dt_seen: 0.0,
            retired_time: 0.0,
            retired_frames: 0,
            steps: Vec::new(),
            density_error: DensityErrorStats::default(),
            frame_time: st.fluid.dt as f64 * st.fluid.substeps as f64,
            steps_taken: 0,
            sim_time: 0.0,
            rest_density: st.fluid.rest_density,
            spare: spare_iterations(st.fluid.solver),
            iterations: {
                let c = st.fluid.convergence();
                (c.min_iterations, c.max_iterations)
            },
        })
    }

    /// (steps, dt) for the next frame (with cfl: dt the host's estimate, the first
    /// frame's a fluid at rest's).
    pub fn plan(&self, st: &SphState) -> (u32, f32) {
        let f = &st.fluid;
        match f.cfl {
            None => (f.substeps, f.dt),
            Some(_) => {
                let dt = match self.dt_seen {
                    // Before any step: the GPU's limit for a fluid at rest.
                    0.0 => {
                        let speed = f.sound().max(1e-6);
                        f.dt_max
                            .unwrap_or(f.dt)
                            .min(f.cfl.unwrap_or(1.0) * f.h / speed)
                    }
                    d => d,
                };
                let behind = self.retired_frames as f64 * self.frame_time - self.retired_time;
                let want = self.frame_time + behind - self.extra.iter().sum::<f64>();
                let steps = (want / dt as f64)
                    .ceil()
                    .clamp(1.0, super::params::MAX_SUBSTEPS as f64)
                    as u32;
                (steps, dt)
            }
        }
    }

    /// Record one frame of steps (with the frame's `hooks`) and the state's health for
    /// this slot.
    pub fn record_frame(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        solver: &SphSolver,
        st: &mut SphState,
        (slot, hooks): (usize, &mut super::hooks::Hooks),
    ) -> Result<()> {
        let (steps, dt) = self.plan(st);
        st.dt = dt;
        st.iteration_bound = self.bound;
        self.pending[slot] = (steps, self.bound);
        if st.fluid.cfl.is_some() {
            self.extra[slot] = steps as f64 * dt as f64 - self.frame_time;
        }
        self.recorded[slot].clear();
        for k in 0..steps {
            solver.record_hooked_step(ctx, cmd, prof, st, hooks)?;
            self.recorded[slot].push(st.commands);
            {
                let _scope = prof.open(ctx, cmd, StepErrors::NAME);
                self.errors.record(ctx, cmd, st, slot, k)?;
            }
        }
        self.errors.record_frame_end(ctx, cmd, slot);
        self.steps_taken += steps as u64;
        self.sim_time += steps as f64 * dt as f64;
        {
            let _scope = prof.open(ctx, cmd, SPH_HEALTH_SCOPE);
            self.health.record(ctx, cmd, st, slot);
        }
        Ok(())
    }

    /// Record at most `bound` iterations per solve (density, divergence) from the next
    /// frame on, as if the last frame had set it (tests force a short bound to see it
    /// caught).
    pub fn force_bound(&mut self, bound: [u32; 2]) {
        self.bound = bound;
    }

    /// The run's density error statistics, with the state's neighbour list overflows
    /// (read once the device is idle).
    pub fn error_stats(&self, st: &SphState) -> DensityErrorStats {
        DensityErrorStats {
            list_overflows: st.list_overflows(),
            ..self.density_error.clone()
        }
    }

    /// After a slot's fence: stop on an unstable frame; update v_max for CFL and the
    /// iterations the next frame records.
    ///
    /// Iterations past convergence cost empty indirect dispatches, which are not free
    /// (on lavapipe about 0.2 ms each, against 5 to 20 ms for a real one; on an H100
    /// about 9 us each with its barrier, which made up half of a 64K DFSPH step when a
    /// frame recorded twice the most iterations used plus 4). So a frame records the most
    /// iterations any step of the last finished frame took plus its [`spare_iterations`], up
    /// to max_iter; a solve that ran out of them before it stopped (it ended above its
    /// target) is counted in `bounded_steps`, the next frame records twice as many, and
    /// the spare grows by one.
    pub fn retire_slot(&mut self, slot: usize, frame: u64) -> Result<()> {
        self.health.check(slot, frame, self.rest_density)?;
        let (steps, recorded) = self.pending[slot];
        let mut t = self.retired_time;
        let (_, max_iter) = self.iterations;
        let cap = |b: u32| if b == 0 { max_iter } else { b.min(max_iter) };
        let mut most = [0u32; 2];
        let mut hit = false;
        let recorded_steps = std::mem::take(&mut self.recorded[slot]);
        for (k, e) in self.errors.read(slot, steps).into_iter().enumerate() {
            t += e.dt as f64;
            let used = [e.iterations, e.divergence_iterations];
            if let Some(c) = recorded_steps.get(k) {
                self.commands.add(c, used);
            }
            for d in 0..2 {
                most[d] = most[d].max(used[d]);
                let ran_out = used[d] >= cap(recorded[d]) && !e.stopped[d];
                if used[d] > 0 && ran_out && cap(recorded[d]) < max_iter {
                    hit = true;
                    self.density_error.bounded_steps += 1;
                    self.last_bounded_frame = Some(frame);
                }
            }
            self.density_error.add(&e);
            self.steps.push((frame, k as u32, t, e));
            self.dt_seen = e.dt;
        }
        // The frame's time as the GPU took it, in place of the estimate it was recorded with.
        let span = t - self.retired_time;
        self.sim_time += span - self.frame_span(slot);
        self.extra[slot] = 0.0;
        self.retired_time = t;
        self.retired_frames += 1;
        if hit {
            self.spare = (self.spare + 1).min(MOST_SPARE);
        }
        self.bound = match hit {
            true => recorded.map(|r| (2 * cap(r)).min(max_iter)),
            false => most.map(|m| (m + self.spare).min(max_iter)),
        };
        Ok(())
    }

    /// The time the slot's frame was recorded to cover (steps x the planned dt).
    fn frame_span(&self, slot: usize) -> f64 {
        self.frame_time + self.extra[slot]
    }

    /// `steps.csv`: one row per step.
    pub fn write_csv(&self, path: &std::path::Path) -> Result<()> {
        let mut out = String::from(
            "frame,step,time,dt,iterations,density_error_mean,density_error_max,\
             divergence_iterations,divergence_error,particles\n",
        );
        for (frame, k, t, e) in &self.steps {
            // WCSPH solves no pressure system: 0 iterations; only DFSPH has a divergence solve.
            out += &format!(
                "{frame},{k},{t:.6},{:.6e},{},{:.6e},{:.6e},{},{:.6e},{}\n",
                e.dt,
                e.iterations,
                e.mean,
                e.max,
                e.divergence_iterations,
                e.divergence_error,
                e.particles
            );
        }
        std::fs::write(path, out).map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e,
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.health.destroy(ctx);
        self.errors.destroy(ctx);
    }
}

/// Physics checks of a state (the physical part of `stats` in summary.json).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PhysicsStats {
    pub particles: usize,
    /// Particles with a non-finite position or velocity.
    pub nan: usize,
    pub outside_domain: usize,
    #[serde(with = "crate::non_finite_as_null")]
    pub density_mean: f64,
    #[serde(with = "crate::non_finite_as_null")]
    pub density_mean_over_rest: f64,
    #[serde(with = "crate::non_finite_as_null")]
    pub density_min: f64,
    #[serde(with = "crate::non_finite_as_null")]
    pub density_max: f64,
    #[serde(with = "crate::non_finite_as_null")]
    pub max_speed: f64,
}

/// Physics checks of a state: NaNs, particles outside the domain, density statistics.
/// `rest_density`: the fluid's (densities are reported over it too).
pub fn physics_stats(d: &StateDump, domain: &Domain, rest_density: f32) -> PhysicsStats {
    let n = d.pos.len();
    let (lo, hi) = (domain.min, domain.max);
    let nan = d
        .pos
        .iter()
        .zip(&d.vel)
        .filter(|(p, v)| p.iter().chain(v.iter()).any(|x| !x.is_finite()))
        .count();
    let outside = d
        .pos
        .iter()
        .filter(|p| (0..3).any(|k| !(p[k] >= lo[k] && p[k] <= hi[k])))
        .count();
    let rho: Vec<f64> = d.rho_p.iter().map(|r| r[0] as f64).collect();
    let mean = rho.iter().sum::<f64>() / n.max(1) as f64;
    let speed = d
        .vel
        .iter()
        .map(|v| ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) as f64).sqrt())
        .fold(0.0f64, |a, b| {
            if b.is_nan() || a.is_nan() {
                f64::NAN
            } else {
                a.max(b)
            }
        });
    let rho0 = rest_density as f64;
    PhysicsStats {
        particles: n,
        nan,
        outside_domain: outside,
        density_mean: mean,
        density_mean_over_rest: mean / rho0,
        density_min: rho.iter().cloned().fold(f64::INFINITY, f64::min),
        density_max: rho.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        max_speed: speed,
    }
}

/// Fail when the state has NaNs or particles outside the domain.
pub fn check(stats: &PhysicsStats) -> Result<()> {
    if stats.nan != 0 || stats.outside_domain != 0 {
        return Err(Error::Unsupported(format!(
            "the simulation became invalid: {} NaN particle(s), {} outside the domain",
            stats.nan, stats.outside_domain
        )));
    }
    Ok(())
}

crate::impl_destroy!(Stepper);
