//! A scene's emission as it plays: the emitter lent to each step, its per-frame metrics
//! (births per triangle, uniformity) and stats.emission.
use crate::character::Mesh;
use crate::emission::emitter::Emitter;
use crate::emission::EmitterKind;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, MemoryLocation};
use serde::{Deserialize, Serialize};

/// One frame of emission.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EmissionRow {
    pub frame: u64,
    pub time: f64,
    pub alive: u32,
    pub births: u32,
    /// Mean over the frame's births (m/s; NaN without births).
    pub birth_speed: f64,
    pub surface_speed: f64,
}

/// `stats.emission` of summary.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EmissionStats {
    pub emitter: EmitterKind,
    pub slots: u32,
    /// Points a birth picks from: covered texels (uv) or vertices.
    pub sources: u32,
    pub uv_size: Option<[u32; 2]>,
    pub atlas_parts: Option<usize>,
    /// The UVs were generated from the character's capsules (it has none).
    pub generated_uvs: Option<bool>,
    pub life_limit: f32,
    pub rate: Option<f32>,
    pub transfer: f32,
    pub alive_final: u32,
    pub alive_max: u32,
    pub alive_mean: f64,
    pub births: u64,
    pub emitted_per_second: f64,
    #[serde(with = "crate::report::non_finite_as_null")]
    pub birth_speed_mean: f64,
    #[serde(with = "crate::report::non_finite_as_null")]
    pub surface_speed_mean: f64,
    #[serde(flatten)]
    pub uniformity: Uniformity,
}

/// Births per unit area over `buckets` runs of consecutive triangles of about equal area
/// (bind pose): their coefficient of variation, and Poisson's for the same births (the
/// floor a perfectly uniform emitter would show).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Uniformity {
    pub buckets: usize,
    #[serde(with = "crate::report::non_finite_as_null")]
    pub uniformity_cv: f64,
    #[serde(with = "crate::report::non_finite_as_null")]
    pub uniformity_cv_poisson: f64,
}

/// Births per mesh triangle: a uv histogram (per layout triangle, `tri_of` mapping it to
/// the mesh's), or a vertex histogram shared among each vertex's triangles.
pub fn births_per_triangle(mesh: &Mesh, hist: &[u32], tri_of: Option<&[u32]>) -> Vec<f64> {
    let tris = mesh.triangles();
    let mut out = vec![0.0f64; tris];
    match tri_of {
        Some(map) => {
            for (l, &c) in hist.iter().enumerate() {
                out[map[l] as usize] += c as f64;
            }
        }
        None => {
            let mut valence = vec![0u32; mesh.vertices()];
            for &v in &mesh.indices {
                valence[v as usize] += 1;
            }
            for (t, c) in mesh.indices.chunks_exact(3).enumerate() {
                for &v in c {
                    let v = v as usize;
                    out[t] += hist[v] as f64 / valence[v].max(1) as f64;
                }
            }
        }
    }
    out
}

pub fn uniformity(mesh: &Mesh, per_tri: &[f64], buckets: usize) -> Uniformity {
    let area: Vec<f64> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    let total: f64 = area.iter().sum();
    let mut sums: Vec<(f64, f64)> = Vec::new(); // (births, area)
    let (mut b, mut a) = (0.0, 0.0);
    for (t, ar) in area.iter().enumerate() {
        b += per_tri[t];
        a += ar;
        if a >= total / buckets as f64 {
            sums.push((b, a));
            (b, a) = (0.0, 0.0);
        }
    }
    if a > 0.0 {
        sums.push((b, a));
    }
    let births: f64 = sums.iter().map(|s| s.0).sum();
    let dens: Vec<f64> = sums.iter().map(|(b, a)| b / a).collect();
    let mean = dens.iter().sum::<f64>() / dens.len().max(1) as f64;
    let var = dens.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / dens.len().max(1) as f64;
    // Poisson: births in a bucket of area a ~ Poisson(B a / A), density CV ~ 1/sqrt(mean count).
    let poisson = (sums.iter().map(|(_, a)| total / (births * a)).sum::<f64>()
        / sums.len().max(1) as f64)
        .sqrt();
    Uniformity {
        buckets: sums.len(),
        uniformity_cv: if mean > 0.0 {
            var.sqrt() / mean
        } else {
            f64::NAN
        },
        uniformity_cv_poisson: if births > 0.0 { poisson } else { f64::NAN },
    }
}

/// Triangle buckets of the uniformity metric.
pub const BUCKETS: usize = 64;

/// The scene side of an emitter: readbacks per frame slot, the rows, the totals.
pub struct EmissionMetrics {
    readbacks: Vec<Buffer>,
    times: Vec<(u64, f64)>,
    pub rows: Vec<EmissionRow>,
}

impl EmissionMetrics {
    pub fn new(ctx: &Context, slots: usize) -> Result<Self> {
        let mut readbacks = crate::gpu::Guard::new(ctx, Vec::new());
        for _ in 0..slots {
            readbacks.push(ctx.create_buffer(
                "emission readback",
                32,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?);
        }
        Ok(Self {
            readbacks: readbacks.take(),
            times: vec![(0, 0.0); slots],
            rows: Vec::new(),
        })
    }

    /// After the frame's steps: its counters into `slot`, the frame counters cleared.
    pub fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        e: &Emitter,
        slot: usize,
        frame: u64,
        t: f64,
    ) {
        self.times[slot] = (frame, t);
        let rb = &self.readbacks[slot];
        ctx.copy(cmd, &e.pass.stats, 0, rb, 0, 16);
        ctx.copy(cmd, &e.pass.counts, 0, rb, 16, 16);
        ctx.host_reads(cmd, &[rb]);
        e.pass.record_clear_stats(ctx, cmd);
    }

    pub fn retire(&mut self, slot: usize) {
        let v: [u32; 8] =
            bytemuck::pod_read_unaligned(self.readbacks[slot].mapped().expect("mapped"));
        let (frame, time) = self.times[slot];
        let mean = |sum: u32| match v[0] {
            0 => f64::NAN,
            b => sum as f64 * 0.01 / b as f64,
        };
        self.rows.push(EmissionRow {
            frame,
            time,
            alive: v[5],
            births: v[0],
            birth_speed: mean(v[1]),
            surface_speed: mean(v[2]),
        });
    }

    /// `stats.emission` (after the run; reads the histogram) and emission.csv in `out`.
    pub fn finish(
        &mut self,
        ctx: &Context,
        e: &Emitter,
        mesh: &Mesh,
        (slots, seconds): (u32, f64),
        out: &std::path::Path,
    ) -> Result<EmissionStats> {
        self.rows.sort_by_key(|r| r.frame);
        let hist: Vec<u32> = ctx.readback(&e.pass.hist, 0, e.pass.primitives as usize)?;
        let (tri_of, size, parts, generated) = match &e.source {
            crate::emission::emitter::EmitSource::Uv(uv, l) => (
                Some(l.tri_of.as_slice()),
                Some(uv.size),
                Some(l.parts.len()),
                Some(l.generated),
            ),
            _ => (None, None, None, None),
        };
        let per_tri = births_per_triangle(mesh, &hist, tri_of);
        let births: u64 = self.rows.iter().map(|r| r.births as u64).sum();
        let weighted = |f: fn(&EmissionRow) -> f64| {
            let s: f64 = self
                .rows
                .iter()
                .filter(|r| r.births > 0)
                .map(|r| f(r) * r.births as f64)
                .sum();
            if births > 0 {
                s / births as f64
            } else {
                f64::NAN
            }
        };
        let path = out.join("emission.csv");
        let mut text = String::from("frame,time,alive,births,birth_speed,surface_speed\n");
        for r in &self.rows {
            text += &format!(
                "{},{:.6},{},{},{:.6},{:.6}\n",
                r.frame, r.time, r.alive, r.births, r.birth_speed, r.surface_speed
            );
        }
        std::fs::write(&path, text).map_err(|source| Error::Io {
            path: path.display().to_string(),
            source,
        })?;
        let n = self.rows.len().max(1) as f64;
        Ok(EmissionStats {
            emitter: e.source.kind(),
            slots,
            sources: e.source.sources(),
            uv_size: size,
            atlas_parts: parts,
            generated_uvs: generated,
            life_limit: e.settings.limit,
            rate: e.settings.rate,
            transfer: e.settings.transfer,
            alive_final: self.rows.last().map_or(0, |r| r.alive),
            alive_max: self.rows.iter().map(|r| r.alive).max().unwrap_or(0),
            alive_mean: self.rows.iter().map(|r| r.alive as f64).sum::<f64>() / n,
            births,
            emitted_per_second: if seconds > 0.0 {
                births as f64 / seconds
            } else {
                0.0
            },
            birth_speed_mean: weighted(|r| r.birth_speed),
            surface_speed_mean: weighted(|r| r.surface_speed),
            uniformity: uniformity(mesh, &per_tri, BUCKETS),
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in &mut self.readbacks {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(EmissionMetrics);

/// The emitter (lent to the solver's steps as a hook), its metrics, and which character
/// sheds.
pub struct SceneEmission {
    pub emitter: Emitter,
    pub metrics: EmissionMetrics,
    /// Index of the emitting character in the scene's characters.
    pub character: usize,
    pub slots: u32,
    /// The source has taken a frame (the first frame primes the previous one too).
    pub primed: bool,
}

impl SceneEmission {
    pub fn destroy(&mut self, ctx: &Context) {
        self.metrics.destroy(ctx);
        self.emitter.destroy(ctx);
    }
}
crate::impl_destroy!(SceneEmission);
