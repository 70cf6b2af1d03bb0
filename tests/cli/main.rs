//! The command line end to end: devices, run, and clear errors with non-zero exits.
#[path = "../common/mod.rs"]
mod common;
use common::{fluidform, summary, text};

mod limits;
mod scenes;
mod surface;
mod view;

#[test]
fn devices_lists_lavapipe_with_features() {
    let o = fluidform(&["devices"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("llvmpipe"), "{t}");
    assert!(t.contains("all required features present"), "{t}");
    assert!(t.contains("timestampPeriod"), "{t}");
    let o = fluidform(&["devices", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let d = &v.as_array().unwrap()[0];
    for key in [
        "name",
        "type",
        "driver",
        "api",
        "timestamp_period_ns",
        "subgroup_size",
        "missing",
    ] {
        assert!(d.get(key).is_some(), "missing {key} in {d}");
    }
}

#[test]
fn run_writes_frames_timings_and_summary() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = fluidform(&[
        "run",
        "--scene",
        "orbits",
        "--frames",
        "3",
        "--out",
        out.to_str().unwrap(),
        "--validation",
        "--width",
        "160",
        "--height",
        "120",
        "--particles",
        "500",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    for f in 0..3 {
        let png = out.join(format!("frame_{f:04}.png"));
        let img = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert_eq!((img.width(), img.height()), (160, 120));
        // Some particles were drawn: not every pixel is the clear colour.
        let rgba = img.to_rgba8();
        let lit = rgba.pixels().filter(|p| p[0] > 40 || p[1] > 40).count();
        assert!(lit > 100, "frame {f}: only {lit} lit pixels");
    }
    let csv = std::fs::read_to_string(out.join("timings.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("frame,pass,ms,start_ms"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    for pass in ["frame", "simulate", "points", "readback"] {
        let n = rows.iter().filter(|r| r[1] == pass).count();
        assert_eq!(n, 3, "pass {pass} rows");
    }
    for r in &rows {
        let ms: f64 = r[2].parse().unwrap();
        assert!(ms >= 0.0 && ms.is_finite());
        // Each pass starts inside its frame.
        let start: f64 = r[3].parse().unwrap();
        assert!(start >= 0.0 && start.is_finite(), "{r:?}");
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(s["device"]["name"].as_str().unwrap().contains("llvmpipe"));
    for key in ["type", "driver", "api"] {
        assert!(s["device"][key].is_string(), "device.{key}");
    }
    assert_eq!(s["frames"], 3);
    assert_eq!(s["config"]["switches"]["width"], 160);
    assert_eq!(s["config"]["particles"], 500);
    for pass in ["simulate", "points", "readback"] {
        let p = &s["pass_ms"][pass];
        let (lo, med, hi) = (
            p["min"].as_f64().unwrap(),
            p["median"].as_f64().unwrap(),
            p["max"].as_f64().unwrap(),
        );
        assert!(0.0 <= lo && lo <= med && med <= hi, "{pass}: {p}");
    }
    let fm = s["frame_ms"]["median"].as_f64().unwrap();
    assert!((s["fps"].as_f64().unwrap() - 1000.0 / fm).abs() < 1e-6);
    // The wall clock's pace beside the GPU's, and the log names the host where it led.
    let wall = s["wall_ms"]["median"].as_f64().unwrap();
    assert!(wall > 0.0 && wall.is_finite(), "{}", s["wall_ms"]);
    assert_eq!(
        text(&o).contains("the host set the pace"),
        wall > 1.25 * fm,
        "wall {wall} ms, GPU {fm} ms: {}",
        text(&o)
    );
    assert!(s["memory_bytes"]["particle positions"].as_u64().unwrap() >= 500 * 16);
    assert_eq!(s["validation"]["errors"], 0);
    assert_eq!(s["validation"]["warnings"], 0);
}

#[test]
fn unknown_switch_value_is_a_clear_error() {
    let o = fluidform(&["run", "--frames", "1", "--sort", "quick"]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(
        t.contains("invalid value 'quick'") && t.contains("odd-even"),
        "{t}"
    );
}

#[test]
fn missing_device_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let o = fluidform(&[
        "run",
        "--frames",
        "1",
        "--device",
        "no-such-gpu",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(
        t.contains("no Vulkan device found matching --device 'no-such-gpu'"),
        "{t}"
    );
    assert!(t.contains("llvmpipe"), "the error lists the devices: {t}");
    let o = fluidform(&[
        "run",
        "--frames",
        "1",
        "--device",
        "7",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(!text(&o).contains("panicked"), "{}", text(&o));
    assert!(
        text(&o).contains("no Vulkan device found matching --device '7'"),
        "{}",
        text(&o)
    );
}

/// Long because it is a table of (command line, the error it must print).
#[test]
fn unimplemented_switches_and_bad_values_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    for (args, needle) in [
        (
            vec!["run", "--scene", "demo", "--frames", "1", "--out", d, "--placement", "random"],
            "--placement does not apply to SPH scenes drawn as metaballs: it is used by scenes with a [control] target",
        ),
        (
            vec![
                "run",
                "--scene",
                "orbits",
                "--frames",
                "1",
                "--out",
                d,
                "--material",
                "glass",
            ],
            "--material does not apply to the orbits scene",
        ),
        (
            vec![
                "run",
                "--scene",
                "orbits",
                "--frames",
                "1",
                "--out",
                d,
                "--neighbors",
                "grid",
            ],
            "--neighbors does not apply to the orbits scene",
        ),
        (
            vec![
                "run", "--scene", "drop", "--render", "points", "--frames", "1", "--out", d,
                "--list", "abuffer",
            ],
            "--list does not apply to SPH scenes drawn as points",
        ),
        (
            vec![
                "run", "--scene", "drop", "--frames", "1", "--out", d, "--fov", "200",
            ],
            "field of view",
        ),
        (
            vec![
                "run", "--scene", "drop", "--frames", "1", "--out", d, "--eye", "1,2",
            ],
            "three finite numbers",
        ),
        (
            vec![
                "run",
                "--frames",
                "1",
                "--out",
                d,
                "--neighbors",
                "morton",
                "--sort",
                "counting",
            ],
            "--sort odd-even or bitonic",
        ),
        (
            vec!["run", "--frames", "1", "--out", d, "--scene", "nope"],
            "unknown scene 'nope'",
        ),
        (vec!["run", "--frames", "0", "--out", d], "0 is not in 1.."),
        (
            vec!["run", "--frames", "1", "--out", d, "--width", "0"],
            "0 is not in 1..=16384",
        ),
        (
            vec!["run", "--frames", "1", "--out", d, "--particles", "0"],
            "0 is not in 1..=67108864",
        ),
        (
            vec!["bench", "render", "--out", d, "--radius=-1"],
            "--radius must be positive",
        ),
        (
            vec!["bench", "nothing", "--out", d],
            "unrecognized subcommand 'nothing'",
        ),
        // Each benchmark takes only its switches: the parser refuses the others.
        (
            vec!["bench", "sph", "--out", d, "--list", "sbuffer"],
            "unexpected argument '--list'",
        ),
        (
            vec!["bench", "scan", "--out", d, "--neighbors", "grid"],
            "unexpected argument '--neighbors'",
        ),
    ] {
        let o = fluidform(&args);
        let t = text(&o);
        assert!(!o.status.success(), "{args:?} succeeded: {t}");
        assert!(t.contains(needle), "{args:?}: {t}");
        assert!(!t.contains("panicked"), "{args:?}: {t}");
    }
}

/// `run` with `args`, no frames saved, validation on, into `dir`: must succeed; the summary.
fn run_ok(dir: &std::path::Path, args: &[&str]) -> serde_json::Value {
    let mut all = vec!["run"];
    all.extend_from_slice(args);
    all.extend([
        "--save-every",
        "0",
        "--out",
        dir.to_str().unwrap(),
        "--validation",
    ]);
    let o = fluidform(&all);
    assert!(o.status.success(), "{}", text(&o));
    summary(dir)
}
