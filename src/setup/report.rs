//! Output contract (DESIGN.md): timings.csv (frame,pass,ms) and summary.json.
use crate::error::{Error, Result};
use crate::gpu::{DeviceInfo, FrameTiming};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
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

/// `device` in summary.json.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct DeviceSummary {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub driver: String,
    pub api: String,
}

impl DeviceSummary {
    pub fn of(d: &DeviceInfo) -> Self {
        Self {
            name: d.name.clone(),
            kind: d.kind.clone(),
            driver: d.driver.clone(),
            api: d.api.clone(),
        }
    }
}

/// `validation` in summary.json.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct ValidationCounts {
    pub errors: u32,
    pub warnings: u32,
}

/// `pass_ms`: per-pass statistics by scope key, in the order the passes first ran.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassTimes(pub Vec<(String, Stat)>);

impl PassTimes {
    pub fn get(&self, key: &str) -> Option<&Stat> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, s)| s)
    }
}

impl Serialize for PassTimes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

impl<'de> Deserialize<'de> for PassTimes {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = PassTimes;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a map of pass keys to statistics")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut a: A,
            ) -> std::result::Result<PassTimes, A::Error> {
                let mut v = Vec::new();
                while let Some(e) = a.next_entry::<String, Stat>()? {
                    v.push(e);
                }
                Ok(PassTimes(v))
            }
        }
        d.deserialize_map(V)
    }
}

/// summary.json (DESIGN.md's output contract): `C` the command's configuration, `S` its
/// area's statistics.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary<C, S> {
    pub device: DeviceSummary,
    pub config: C,
    pub frames: usize,
    pub pass_ms: PassTimes,
    pub frame_ms: Option<Stat>,
    /// Wall-clock ms from one frame's start of recording to the next's: the pace the run
    /// kept, host work and waits included (`frame_ms` is the GPU's alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_ms: Option<Stat>,
    /// 1000 / median GPU frame time.
    pub fps: Option<f64>,
    pub memory_bytes: BTreeMap<String, u64>,
    pub stats: S,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation: Option<ValidationCounts>,
    /// Barriers the tracker placed beyond the hand-placed ones, and hazards it found in
    /// draws where it may place none (`gpu::track`; both 0 when the hand placement is
    /// complete).
    #[serde(default)]
    pub barriers: TrackedBarriers,
    /// The build and the time it was measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<crate::provenance::Provenance>,
}

#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct TrackedBarriers {
    pub placed: u64,
    pub unplaced: u64,
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    }
}

/// What one `run` or `bench` measured.
pub struct Report<'a, C, S> {
    pub device: &'a DeviceInfo,
    pub config: C,
    pub timings: &'a [FrameTiming],
    pub memory: BTreeMap<String, u64>,
    pub stats: S,
    pub validation: Option<(u32, u32)>,
    /// `Context::tracked_barriers`.
    pub barriers: (u64, u64),
}

impl<C: Serialize + Clone, S: Serialize + Clone> Report<'_, C, S> {
    pub fn summary(&self) -> Summary<C, S> {
        let frame: Vec<f64> = self.timings.iter().map(|t| t.frame_ms).collect();
        let frame_ms = stat(&frame);
        let mut begins: Vec<(u64, f64)> = (self.timings.iter())
            .filter_map(|t| Some((t.frame, t.cpu_ns?.0)))
            .collect();
        begins.sort_by_key(|b| b.0);
        let paces: Vec<f64> = begins
            .windows(2)
            .filter(|w| w[1].0 == w[0].0 + 1)
            .map(|w| (w[1].1 - w[0].1) * 1e-6)
            .collect();
        Summary {
            device: DeviceSummary::of(self.device),
            config: self.config.clone(),
            frames: self.timings.len(),
            pass_ms: PassTimes(pass_stats(self.timings)),
            frame_ms,
            wall_ms: stat(&paces),
            fps: frame_ms
                .filter(|s| s.median > 0.0)
                .map(|s| 1000.0 / s.median),
            memory_bytes: self.memory.clone(),
            stats: self.stats.clone(),
            validation: self
                .validation
                .map(|(errors, warnings)| ValidationCounts { errors, warnings }),
            barriers: TrackedBarriers {
                placed: self.barriers.0,
                unplaced: self.barriers.1,
            },
            provenance: Some(crate::provenance::Provenance::now(
                Some(self.timings.len() as u64),
                None,
            )),
        }
    }

    /// Write timings.csv and summary.json into `dir` (created if missing).
    pub fn write(&self, dir: &Path) -> Result<Summary<C, S>> {
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
        // start_ms: where the pass starts, ms after the frame's start (the frame: 0).
        w.write_record(["frame", "pass", "ms", "start_ms"])
            .map_err(csv_err)?;
        for t in self.timings {
            let frame = t.frame.to_string();
            let ms = format!("{:.6}", t.frame_ms);
            w.write_record([frame.as_str(), "frame", &ms, "0.000000"])
                .map_err(csv_err)?;
            for (k, (name, ms)) in t.passes.iter().enumerate() {
                let start = t.starts.get(k).copied().unwrap_or(f64::NAN);
                w.write_record([
                    frame.as_str(),
                    name.as_str(),
                    &format!("{ms:.6}"),
                    &format!("{start:.6}"),
                ])
                .map_err(csv_err)?;
            }
        }
        w.flush().map_err(io(&csv_path))?;
        let summary = self.summary();
        let path = dir.join("summary.json");
        let text = serde_json::to_string_pretty(&summary).map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e.into(),
        })?;
        std::fs::write(&path, text + "\n").map_err(io(&path))?;
        Ok(summary)
    }
}

pub use fluidform_sim::non_finite_as_null;

impl<C, S> Summary<C, S> {
    /// The median milliseconds of the scope `key`; an error naming the scopes recorded
    /// when it was not.
    pub fn pass_median(&self, key: crate::gpu::ScopeKey) -> Result<f64> {
        let p = &self.pass_ms;
        p.get(key.path())
            .map(|s| s.median)
            .ok_or_else(|| key.missing(p.0.iter().map(|(k, _)| k.as_str())))
    }
}
