//! Output contract (DESIGN.md): timings.csv (frame,pass,ms) and summary.json.
use crate::error::{Error, Result};
use crate::gpu::{DeviceInfo, FrameTiming};
use serde::Serialize;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Stat {
    pub median: f64,
    pub min: f64,
    pub max: f64,
}

/// Median (mean of the middle two for even counts), min and max; None when empty.
pub fn stat(values: &[f64]) -> Option<Stat> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    let median = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    Some(Stat {
        median,
        min: v[0],
        max: v[n - 1],
    })
}

/// Per-pass statistics in first-seen order; a pass run several times in a frame is summed.
pub fn pass_stats(timings: &[FrameTiming]) -> Vec<(String, Stat)> {
    let mut order: Vec<String> = Vec::new();
    let mut per: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for t in timings {
        let mut frame: BTreeMap<&str, f64> = BTreeMap::new();
        for (name, ms) in &t.passes {
            if !order.contains(name) {
                order.push(name.clone());
            }
            *frame.entry(name).or_default() += ms;
        }
        for (name, ms) in frame {
            per.entry(name.to_string()).or_default().push(ms);
        }
    }
    order
        .into_iter()
        .filter_map(|n| stat(&per[&n]).map(|s| (n, s)))
        .collect()
}

pub fn device_json(d: &DeviceInfo) -> Value {
    json!({ "name": d.name, "type": d.kind, "driver": d.driver, "api": d.api })
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    }
}

/// What one `run` or `bench` measured.
pub struct Report<'a> {
    pub device: &'a DeviceInfo,
    pub config: Value,
    pub timings: &'a [FrameTiming],
    pub memory: BTreeMap<String, u64>,
    pub stats: Value,
    pub validation: Option<(u32, u32)>,
}

impl Report<'_> {
    pub fn summary(&self) -> Value {
        let mut pass_ms = Map::new();
        for (name, s) in pass_stats(self.timings) {
            pass_ms.insert(name, json!(s));
        }
        let frame: Vec<f64> = self.timings.iter().map(|t| t.frame_ms).collect();
        let frame_ms = stat(&frame);
        let fps = frame_ms
            .filter(|s| s.median > 0.0)
            .map(|s| 1000.0 / s.median);
        let mut v = json!({
            "device": device_json(self.device),
            "config": self.config,
            "frames": self.timings.len(),
            "pass_ms": pass_ms,
            "frame_ms": frame_ms,
            "fps": fps,
            "memory_bytes": self.memory,
            "stats": self.stats,
        });
        if self.device.name.contains("llvmpipe")
            && self
                .timings
                .iter()
                .any(|t| t.passes.iter().any(|(n, _)| n == "draw"))
        {
            // Measured here: once a framebuffer is bound, llvmpipe resolves some later
            // timestamps inside its rasterizer scene, so compute scopes of frames after a
            // draw can read near zero while frame_ms stays right.
            v["timing_caveat"] = json!(
                "llvmpipe: per-pass compute times after a draw are unreliable (frame_ms is right); use `fluidform bench` for per-pass times"
            );
        }
        if let Some((errors, warnings)) = self.validation {
            v["validation"] = json!({ "errors": errors, "warnings": warnings });
        }
        v
    }

    /// Write timings.csv and summary.json into `dir` (created if missing).
    pub fn write(&self, dir: &Path) -> Result<Value> {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let csv_path = dir.join("timings.csv");
        let mut w = csv::Writer::from_path(&csv_path).map_err(|e| Error::Io {
            path: csv_path.display().to_string(),
            source: e.into(),
        })?;
        let csv_err = |e: csv::Error| Error::Io {
            path: csv_path.display().to_string(),
            source: e.into(),
        };
        w.write_record(["frame", "pass", "ms"]).map_err(csv_err)?;
        for t in self.timings {
            let frame = t.frame.to_string();
            w.write_record([frame.as_str(), "frame", &format!("{:.6}", t.frame_ms)])
                .map_err(csv_err)?;
            for (name, ms) in &t.passes {
                w.write_record([frame.as_str(), name.as_str(), &format!("{ms:.6}")])
                    .map_err(csv_err)?;
            }
        }
        w.flush().map_err(io(&csv_path))?;
        let summary = self.summary();
        let path = dir.join("summary.json");
        let text = serde_json::to_string_pretty(&summary).expect("json");
        std::fs::write(&path, text + "\n").map_err(io(&path))?;
        Ok(summary)
    }
}
