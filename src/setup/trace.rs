//! `--trace FILE`: the GPU passes of every frame as Chrome trace JSON (the Trace Event
//! Format), which Perfetto (ui.perfetto.dev) and chrome://tracing open. Each frame is one
//! complete event on the GPU track with its scopes nested inside by time; where the device
//! has calibrated timestamps (`gpu::clock`), the GPU times are put on the CPU's clock and a
//! CPU track shows when each frame was recorded and submitted. Without them the trace is
//! GPU time only, from the first frame's start.
use crate::error::{Error, Result};
use crate::gpu::clock::Calibration;
use crate::gpu::FrameTiming;
use serde_json::{json, Value};
use std::path::Path;

const GPU_PID: u32 = 1;
const CPU_PID: u32 = 2;

/// One traced frame: its timings, and what it ran (a benchmark's case, "" for a run).
pub struct Traced<'a> {
    pub label: &'a str,
    pub timing: &'a FrameTiming,
}

/// The trace as JSON: `{"traceEvents": [...], "displayTimeUnit": "ms", "otherData": ...}`.
pub fn trace_json(frames: &[Traced], cal: Option<Calibration>, device: &str) -> Value {
    let origin = frames
        .iter()
        .map(|f| f.timing.gpu_ns)
        .fold(f64::INFINITY, f64::min);
    // µs on the timeline: the CPU's clock where calibrated, else from the first frame.
    let gpu_us = |ns: f64| match cal {
        Some(c) => c.to_cpu(ns) / 1e3,
        None => (ns - origin) / 1e3,
    };
    let mut events = vec![
        meta(
            "process_name",
            GPU_PID,
            json!({ "name": format!("GPU: {device}") }),
        ),
        meta("thread_name", GPU_PID, json!({ "name": "queue" })),
    ];
    if cal.is_some() {
        events.push(meta("process_name", CPU_PID, json!({ "name": "CPU" })));
        events.push(meta(
            "thread_name",
            CPU_PID,
            json!({ "name": "record and submit" }),
        ));
    }
    for f in frames {
        let t = f.timing;
        let name = match f.label {
            "" => format!("frame {}", t.frame),
            l => format!("{l} frame {}", t.frame),
        };
        let start = gpu_us(t.gpu_ns);
        events.push(complete(
            &name,
            GPU_PID,
            start,
            t.frame_ms * 1e3,
            f.label,
            t.frame,
            "frame",
        ));
        for (k, ((key, ms), s)) in t.passes.iter().zip(&t.starts).enumerate() {
            let short = key.rsplit('/').next().unwrap_or(key);
            let (ts, dur) = (start + s * 1e3, ms * 1e3);
            let mut e = complete(short, GPU_PID, ts, dur, f.label, t.frame, key);
            // The scope it was opened inside: its index among the frame's passes.
            e["args"]["index"] = json!(k);
            e["args"]["parent"] = json!(t.parents.get(k).copied().flatten());
            events.push(e);
        }
        if let (Some(_), Some((b, e))) = (cal, t.cpu_ns) {
            let d = (e - b) / 1e3;
            events.push(complete(
                &name,
                CPU_PID,
                b / 1e3,
                d,
                f.label,
                t.frame,
                "record",
            ));
        }
    }
    json!({
        "traceEvents": events,
        "displayTimeUnit": "ms",
        "otherData": {
            "device": device,
            "clock": match cal {
                Some(_) => "CLOCK_MONOTONIC (GPU timestamps calibrated onto it)",
                None => "GPU timestamps only, from the first frame's start (no calibrated timestamps)",
            },
            "calibration_deviation_ns": cal.map(|c| c.deviation_ns),
        },
    })
}

fn meta(what: &str, pid: u32, args: Value) -> Value {
    json!({ "name": what, "ph": "M", "pid": pid, "tid": 1, "args": args })
}

fn complete(name: &str, pid: u32, ts: f64, dur: f64, label: &str, frame: u64, key: &str) -> Value {
    json!({
        "name": name, "cat": if pid == GPU_PID { "gpu" } else { "cpu" }, "ph": "X",
        "pid": pid, "tid": 1, "ts": ts, "dur": dur,
        "args": { "frame": frame, "case": label, "key": key },
    })
}

/// Write the trace of `frames` to `path`.
pub fn write_trace(
    path: &Path,
    frames: &[Traced],
    cal: Option<Calibration>,
    device: &str,
) -> Result<()> {
    let io = |e: std::io::Error| Error::Io {
        path: path.display().to_string(),
        source: e,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let text = serde_json::to_string(&trace_json(frames, cal, device))
        .map_err(|e| Error::Param(format!("trace: {e}")))?;
    std::fs::write(path, text).map_err(io)
}

/// `--trace FILE` of a run: every frame of `timings`, calibrated where the device can.
pub fn write_run_trace(
    ctx: &crate::gpu::Context,
    path: &Path,
    timings: &[FrameTiming],
) -> Result<()> {
    let frames: Vec<Traced> = timings
        .iter()
        .map(|t| Traced {
            label: "",
            timing: t,
        })
        .collect();
    let cal = crate::gpu::clock::calibrate(ctx);
    write_trace(path, &frames, cal, &ctx.info.name)
}
