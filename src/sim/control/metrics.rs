//! Metrics of a control target, every frame (`control.csv`, and `stats.control` of
//! summary.json): the fidelity metrics (`super::fidelity`: fill, IoU near the target,
//! spray, surface distance, density in the shape, speed excess) with their means and
//! minima over a window, and the thesis's own: the fluid of the controlled groups inside
//! the current (skinned) target, control particles covered by fluid (density >= 50%
//! rho_0), the fluid's density error.
use super::fidelity;
use super::force::{ControlForce, ALL_GROUPS};
pub use super::metrics_worker::Skin;
use super::metrics_worker::{Job, Workers};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, MemoryLocation};
use crate::sph::SphState;
use glam::Vec3;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ControlRow {
    pub frame: u64,
    pub time: f64,
    pub target: String,
    pub fill: f64,
    pub iou: f64,
    pub spray: f64,
    pub surface_p95: f64,
    /// Empty: no fluid inside the target.
    pub density_in_shape: Option<f64>,
    pub speed_excess: f64,
    /// The fastest skin point (m/s).
    pub skin_speed: f64,
    pub inside_fraction: f64,
    pub coverage: f64,
    pub density_error_mean: f64,
    pub density_error_max: f64,
    /// Largest rho / rho_0 (compression).
    pub density_ratio_max: f64,
    pub control_particles: u32,
}

/// `stats.control` of summary.json.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ControlStats {
    pub target: String,
    pub placement: Option<crate::control::Placement>,
    pub control_particles: u32,
    pub settings: Option<super::force::ControlSettings>,
    /// First scene time at which `fill` reached 0.9 (None: never).
    pub time_to_90: Option<f64>,
    /// The fidelity metrics' mean and minimum over the window.
    pub fidelity: Option<Window>,
    /// First scene time at which coverage reached 0.9 (None: never)...
    pub coverage_time_to_90: Option<f64>,
    /// ... and 0.8 (a filled shape's coverage plateaus near 0.85: control particles
    /// within a kernel radius of the surface see a free surface's partial density).
    pub coverage_time_to_80: Option<f64>,
    /// The target's animation cycle in scene seconds (clip duration / speed), and the
    /// mean inside fraction over the run's last cycle (None: no clip, or a shorter run).
    pub cycle_s: Option<f64>,
    pub mean_inside_last_cycle: Option<f64>,
    pub last: Option<ControlRow>,
    /// Means over every frame.
    pub mean_inside_fraction: f64,
    pub mean_coverage: f64,
    /// Frames where the fluid was compressed beyond the kernels' valid band
    /// (rho / rho_0 > 1.5 somewhere): control forces too strong for the spacing.
    pub frames_out_of_band: u64,
}

/// Mean and minimum of one metric over the window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeanMin {
    pub mean: f64,
    pub min: f64,
    pub max: f64,
}

impl MeanMin {
    fn of(v: impl Iterator<Item = f64>) -> Option<Self> {
        let v: Vec<f64> = v.collect();
        (!v.is_empty()).then(|| Self {
            mean: v.iter().sum::<f64>() / v.len() as f64,
            min: v.iter().cloned().fold(f64::INFINITY, f64::min),
            max: v.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// The fidelity metrics summarised over the frames from `from` seconds on (`--metrics-from`,
/// default the second half of the run).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Window {
    pub from: f64,
    pub frames: usize,
    pub fill: Option<MeanMin>,
    pub iou: Option<MeanMin>,
    pub spray: Option<MeanMin>,
    pub surface_p95: Option<MeanMin>,
    pub density_in_shape: Option<MeanMin>,
    pub speed_excess: Option<MeanMin>,
}

/// Per-slot host copies of what the metrics read.
struct Slot {
    pos: Buffer,
    vel: Buffer,
    rho: Buffer,
    attr: Buffer,
    crho: Buffer,
    counts: Buffer,
}

pub struct ControlMetrics {
    slots: Vec<Slot>,
    n: u32,
    m: u32,
    pub rows: Vec<ControlRow>,
    pub stats: ControlStats,
    workers: Workers,
}

impl ControlMetrics {
    pub fn new(ctx: &Context, n: u32, m: u32, target: &str, slots: usize) -> Result<Self> {
        let host = |name: &str, bytes: u64| {
            ctx.create_buffer(
                name,
                bytes,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )
        };
        let mut out = crate::gpu::Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            out.push(host("metrics positions", n as u64 * 16)?);
            out.push(host("metrics velocities", n as u64 * 16)?);
            out.push(host("metrics densities", n as u64 * 8)?);
            out.push(host("metrics attributes", n as u64 * 16)?);
            out.push(host("metrics control densities", m as u64 * 4)?);
            out.push(host("metrics control counts", 16)?);
        }
        let mut it = out.take().into_iter();
        let slots = (0..slots)
            .map(|_| Slot {
                pos: it.next().unwrap(),
                vel: it.next().unwrap(),
                rho: it.next().unwrap(),
                attr: it.next().unwrap(),
                crho: it.next().unwrap(),
                counts: it.next().unwrap(),
            })
            .collect();
        Ok(Self {
            slots,
            n,
            m,
            rows: Vec::new(),
            workers: Workers::new(),
            stats: ControlStats {
                target: target.into(),
                control_particles: m,
                ..Default::default()
            },
        })
    }

    /// Record the copies of the frame's last state into `slot`.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        st: &SphState,
        force: &ControlForce,
        slot: usize,
    ) -> Result<()> {
        let s = &self.slots[slot];
        ctx.copy(cmd, st.pos(), 0, &s.pos, 0, self.n as u64 * 16);
        ctx.copy(cmd, st.vel(), 0, &s.vel, 0, self.n as u64 * 16);
        ctx.copy(cmd, st.rho_p(), 0, &s.rho, 0, self.n as u64 * 8);
        ctx.copy(cmd, st.attr(), 0, &s.attr, 0, self.n as u64 * 16);
        force.record_copy_readback(ctx, cmd, &s.crho, &s.counts)?;
        ctx.host_reads(cmd, &[&s.pos, &s.vel, &s.rho, &s.attr, &s.crho, &s.counts]);
        Ok(())
    }

    /// After the slot's fence: queue the row of frame `frame` at scene time `time`, with
    /// the target posed as `skin` says (skinned on the worker, with its skin speed). The
    /// row is computed on a worker thread (metrics_worker.rs); rows already done are folded
    /// in now, the rest by `flush`.
    #[allow(clippy::too_many_arguments)]
    pub fn retire(
        &mut self,
        slot: usize,
        frame: u64,
        time: f64,
        skin: Skin,
        force: &ControlForce,
        group: u32,
        fluid: &fidelity::Fluid,
    ) -> Result<()> {
        let s = &self.slots[slot];
        fn read(b: &Buffer) -> Result<&[u8]> {
            b.mapped()
                .ok_or_else(|| Error::Bug("metrics buffer not mapped".into()))
        }
        let n = self.n as usize;
        let pos: &[[f32; 4]] = bytemuck::cast_slice(&read(&s.pos)?[..n * 16]);
        let vel: &[[f32; 4]] = bytemuck::cast_slice(&read(&s.vel)?[..n * 16]);
        let rho: &[[f32; 2]] = bytemuck::cast_slice(&read(&s.rho)?[..n * 8]);
        let attr: &[[f32; 4]] = bytemuck::cast_slice(&read(&s.attr)?[..n * 16]);
        let counts: &[u32] = bytemuck::cast_slice(&read(&s.counts)?[..16]);
        let live = force
            .check_counts([counts[0], counts[1], counts[2], counts[3]])?
            .min(self.m);
        let crho: &[f32] = bytemuck::cast_slice(&read(&s.crho)?[..live as usize * 4]);
        // Live particles only (emission's dead slots have w < 0).
        let alive: Vec<usize> = (0..n).filter(|&i| pos[i][3] >= 0.0).collect();
        let v3 = |a: &[f32; 4]| Vec3::new(a[0], a[1], a[2]);
        self.workers.send(Job {
            frame,
            time,
            target: self.stats.target.clone(),
            pos: alive.iter().map(|&i| v3(&pos[i])).collect(),
            vel: alive.iter().map(|&i| v3(&vel[i])).collect(),
            rho: alive.iter().map(|&i| rho[i][0]).collect(),
            controlled: (alive.iter())
                .map(|&i| group == ALL_GROUPS || attr[i][3].to_bits() == group)
                .collect(),
            crho: crho.to_vec(),
            skin,
            fluid: *fluid,
            live,
        });
        self.stats.control_particles = live;
        for row in self.workers.ready(false)? {
            let t = row.time;
            self.push(row, t);
        }
        Ok(())
    }

    /// Wait for every queued row and fold it in; call before `finish_cycle` and
    /// `finish_window`.
    pub fn flush(&mut self) -> Result<()> {
        for row in self.workers.ready(true)? {
            let t = row.time;
            self.push(row, t);
        }
        Ok(())
    }

    /// Keep `row` (at scene time `time`) and fold it into the run's statistics.
    fn push(&mut self, row: ControlRow, time: f64) {
        let st = &mut self.stats;
        if st.time_to_90.is_none() && row.fill >= 0.9 {
            st.time_to_90 = Some(time);
        }
        if st.coverage_time_to_90.is_none() && row.coverage >= 0.9 {
            st.coverage_time_to_90 = Some(time);
        }
        if st.coverage_time_to_80.is_none() && row.coverage >= 0.8 {
            st.coverage_time_to_80 = Some(time);
        }
        if row.density_ratio_max > 1.5 {
            st.frames_out_of_band += 1;
        }
        let k = self.rows.len() as f64;
        st.mean_inside_fraction = (st.mean_inside_fraction * k + row.inside_fraction) / (k + 1.0);
        st.mean_coverage = (st.mean_coverage * k + row.coverage) / (k + 1.0);
        st.last = Some(row.clone());
        self.rows.push(row);
    }

    /// The fidelity window: the frames from scene time `from` on (None: the second half
    /// of the rows' time span).
    pub fn finish_window(&mut self, from: Option<f64>) {
        let (Some(a), Some(b)) = (self.rows.first(), self.rows.last()) else {
            return;
        };
        let from = from.unwrap_or(0.5 * (a.time + b.time));
        let rows: Vec<&ControlRow> = self.rows.iter().filter(|r| r.time >= from).collect();
        let of =
            |f: &dyn Fn(&ControlRow) -> Option<f64>| MeanMin::of(rows.iter().filter_map(|r| f(r)));
        self.stats.fidelity = Some(Window {
            from,
            frames: rows.len(),
            fill: of(&|r| Some(r.fill)),
            iou: of(&|r| Some(r.iou)),
            spray: of(&|r| Some(r.spray)),
            surface_p95: of(&|r| Some(r.surface_p95)),
            density_in_shape: of(&|r| r.density_in_shape),
            speed_excess: of(&|r| Some(r.speed_excess)),
        });
    }

    /// `cycle_s` and `mean_inside_last_cycle` for a target animated with period `cycle`.
    pub fn finish_cycle(&mut self, cycle: Option<f64>) {
        let st = &mut self.stats;
        st.cycle_s = cycle;
        st.mean_inside_last_cycle = match (cycle, self.rows.first(), self.rows.last()) {
            (Some(c), Some(a), Some(b)) if b.time - a.time >= c => {
                let from = b.time - c;
                let tail: Vec<f64> = self
                    .rows
                    .iter()
                    .filter(|r| r.time >= from)
                    .map(|r| r.inside_fraction)
                    .collect();
                Some(tail.iter().sum::<f64>() / tail.len() as f64)
            }
            _ => None,
        };
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.workers.stop();
        for s in &mut self.slots {
            for b in [
                &mut s.pos,
                &mut s.vel,
                &mut s.rho,
                &mut s.attr,
                &mut s.crho,
                &mut s.counts,
            ] {
                ctx.destroy_buffer(b);
            }
        }
    }
}
crate::impl_destroy!(ControlMetrics);

/// control.csv: one row per target and frame.
pub fn write_csv(path: &std::path::Path, rows: &[ControlRow]) -> Result<()> {
    let io = |e: std::io::Error| Error::Io {
        path: path.display().to_string(),
        source: e,
    };
    let mut w = csv::Writer::from_path(path).map_err(|e| io(e.into()))?;
    for r in rows {
        w.serialize(r).map_err(|e| io(e.into()))?;
    }
    w.flush().map_err(io)
}
