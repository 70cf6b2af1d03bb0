//! The control metrics' CPU work off the frame loop: a frame's readback is copied into a
//! job and computed on worker threads (the target skinned twice on the CPU for its mesh
//! and skin speed, the fidelity metrics' voxel loop and inside tests, the hash-map
//! density, the thesis's inside fraction), so a frame never waits for them. Rows come
//! back in frame order; every frame still gets its row.
use super::fidelity::{self, Fidelity};
use super::inside::InsideTest;
use super::metrics::ControlRow;
use crate::character::Character;
use crate::character::Skinning;
use crate::error::{Error, Result};
use glam::{Mat4, Vec3};
use std::collections::BTreeMap;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// One frame's inputs, owned (the readback buffers are reused by later frames).
pub(super) struct Job {
    pub frame: u64,
    pub time: f64,
    pub target: String,
    pub pos: Vec<Vec3>,
    pub vel: Vec<Vec3>,
    pub rho: Vec<f32>,
    pub controlled: Vec<bool>,
    /// Densities at the live control particles.
    pub crho: Vec<f32>,
    pub skin: Skin,
    pub fluid: fidelity::Fluid,
    pub live: u32,
}

/// The target's character posed by the frame's joint matrices and morph weights, and by
/// those `dt` seconds before (its skin speed).
pub struct Skin {
    pub ch: Arc<Character>,
    pub mats: (Vec<Mat4>, Vec<f32>),
    pub before: (Vec<Mat4>, Vec<f32>),
    pub method: Skinning,
    pub dt: f64,
}

/// The frame's row: the fidelity metrics, the fluid inside the target, the covered control
/// particles and the density error.
pub(super) fn compute(j: &Job) -> Result<ControlRow> {
    let k = &j.skin;
    let (posed, _) = k.ch.skinned_with(&k.mats.0, &k.mats.1, k.method)?;
    let (prev, _) = k.ch.skinned_with(&k.before.0, &k.before.1, k.method)?;
    let skin_speed = (posed.iter().zip(&prev))
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f32::max)
        / k.dt as f32;
    let mesh = (posed.as_slice(), k.ch.mesh.indices.as_slice());
    // One test for the frame, by the character's own closedness.
    let inside = InsideTest::of(mesh.0, mesh.1, k.ch.check.closed());
    let fid: Fidelity = fidelity::measure(
        &fidelity::Frame {
            pos: &j.pos,
            vel: &j.vel,
            rho: &j.rho,
            controlled: &j.controlled,
        },
        (mesh, &inside),
        skin_speed,
        &j.fluid,
    );
    let rest_density = j.fluid.rest_density;
    let ours: Vec<Vec3> = (j.pos.iter().zip(&j.controlled))
        .filter(|(_, c)| **c)
        .map(|(p, _)| *p)
        .collect();
    let inside_count = ours.iter().filter(|p| inside.inside(**p)).count();
    let covered = j.crho.iter().filter(|&&r| r >= 0.5 * rest_density).count();
    let errs: Vec<f64> = (j.rho.iter())
        .map(|r| (*r as f64 / rest_density as f64 - 1.0).abs())
        .collect();
    Ok(ControlRow {
        frame: j.frame,
        time: j.time,
        target: j.target.clone(),
        fill: fid.fill,
        iou: fid.iou,
        spray: fid.spray,
        surface_p95: fid.surface_p95,
        density_in_shape: fid.density_in_shape,
        speed_excess: fid.speed_excess,
        skin_speed: skin_speed as f64,
        inside_fraction: inside_count as f64 / ours.len().max(1) as f64,
        coverage: covered as f64 / j.live.max(1) as f64,
        density_error_mean: errs.iter().sum::<f64>() / errs.len().max(1) as f64,
        density_error_max: errs.iter().cloned().fold(0.0, f64::max),
        density_ratio_max: (j.rho.iter())
            .map(|r| *r as f64 / rest_density as f64)
            .fold(0.0, f64::max),
        control_particles: j.live,
    })
}

/// Worker threads fed by a queue that never blocks the sender.
pub(super) struct Workers {
    tx: Option<Sender<(u64, Job)>>,
    rx: Receiver<(u64, Result<ControlRow>)>,
    handles: Vec<JoinHandle<()>>,
    sent: u64,
    /// Rows computed out of order, by sequence number, until their turn.
    done: BTreeMap<u64, Result<ControlRow>>,
    next: u64,
}

impl Workers {
    /// Half the machine's threads, one to four.
    pub fn new() -> Self {
        let threads = std::thread::available_parallelism()
            .map(|n| n.get() / 2)
            .unwrap_or(1)
            .clamp(1, 4);
        let (tx, jobs) = channel::<(u64, Job)>();
        let (back, rx) = channel();
        let jobs = Arc::new(Mutex::new(jobs));
        let handles = (0..threads)
            .map(|_| {
                let (jobs, back) = (jobs.clone(), back.clone());
                std::thread::spawn(move || loop {
                    // The lock is held only to take a job, not while computing it.
                    let job = jobs.lock().map(|q| q.recv());
                    let Ok(Ok((seq, job))) = job else {
                        return;
                    };
                    if back.send((seq, compute(&job))).is_err() {
                        return;
                    }
                })
            })
            .collect();
        Self {
            tx: Some(tx),
            rx,
            handles,
            sent: 0,
            done: BTreeMap::new(),
            next: 0,
        }
    }

    /// Queue a frame's job (computed inline if the workers are gone).
    pub fn send(&mut self, job: Job) {
        let seq = self.sent;
        self.sent += 1;
        let failed = match &self.tx {
            Some(tx) => tx.send((seq, job)).err().map(|e| e.0 .1),
            None => Some(job),
        };
        if let Some(job) = failed {
            self.done.insert(seq, compute(&job));
        }
    }

    /// The rows ready in frame order; with `all`, wait for every row sent so far. A frame
    /// whose row failed (its skinning) is the error.
    pub fn ready(&mut self, all: bool) -> Result<Vec<ControlRow>> {
        loop {
            while let Ok((seq, row)) = self.rx.try_recv() {
                self.done.insert(seq, row);
            }
            if !all || self.next + self.done.len() as u64 >= self.sent {
                break;
            }
            match self.rx.recv() {
                Ok((seq, row)) => {
                    self.done.insert(seq, row);
                }
                // Every worker has stopped (none should): nothing more will come.
                Err(_) => break,
            }
        }
        let mut out = Vec::new();
        while let Some(row) = self.done.remove(&self.next) {
            self.next += 1;
            out.push(row?);
        }
        if all && self.next < self.sent {
            return Err(Error::Bug(
                "control metrics: a worker stopped before its rows were done".into(),
            ));
        }
        Ok(out)
    }

    /// Close the queue and join the workers.
    pub fn stop(&mut self) {
        self.tx = None;
        for h in self.handles.drain(..) {
            let _ = h.join();
        }
    }
}
