//! The fidelity switches end to end: the metrics in control.csv and summary.json with
//! their window, the presets (thesis against fidelity), --fluid spacing, --skinning dqs on
//! the control particles, inspect's thinnest part, and bad input.
mod common;
use common::{fluidform, summary, text};

fn run(dir: &std::path::Path, name: &str, frames: &str, extra: &[&str]) -> serde_json::Value {
    let out = dir.join(name);
    let mut args = vec![
        "run",
        "--scene",
        "character",
        "--frames",
        frames,
        "--render",
        "points",
        "--width",
        "64",
        "--height",
        "64",
        "--quiet",
        "--out",
    ];
    let o = out.to_str().unwrap().to_string();
    args.push(&o);
    args.extend_from_slice(extra);
    let r = fluidform(&args);
    assert!(r.status.success(), "{name}: {}", text(&r));
    summary(&out)
}

#[test]
fn metrics_and_presets_work_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let s = run(
        dir.path(),
        "fid",
        "12",
        &["--metrics-from", "0.05", "--validation"],
    );
    let t = &s["stats"]["control"]["targets"][0];
    let w = &t["fidelity"];
    assert!((w["from"].as_f64().unwrap() - 0.05).abs() < 1e-12, "{w}");
    let frames = w["frames"].as_u64().unwrap();
    assert!(
        (6..=8).contains(&frames),
        "frames from 0.05 s at 10.8 ms: {frames}"
    );
    for k in ["fill", "iou", "spray", "surface_p95", "speed_excess"] {
        let m = &w[k];
        let (mean, min) = (m["mean"].as_f64().unwrap(), m["min"].as_f64().unwrap());
        assert!(min <= mean && mean.is_finite(), "{k}: {m}");
    }
    assert!(w["fill"]["max"].as_f64().unwrap() <= 1.0);
    assert_eq!(t["settings"]["motion"], "skin");
    assert!(t["settings"]["attraction"].as_f64().unwrap() > 0.0);
    let csv = std::fs::read_to_string(dir.path().join("fid/control.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    for k in [
        "fill",
        "iou",
        "spray",
        "surface_p95",
        "density_in_shape",
        "speed_excess",
        "inside_fraction",
        "coverage",
    ] {
        assert!(header.split(',').any(|h| h == k), "{k} in {header}");
    }
    assert_eq!(csv.lines().count(), 13);
    // The thesis preset adds nothing to eq. 7; the fidelity one fills faster.
    let th = run(dir.path(), "th", "12", &["--control-preset", "thesis"]);
    let tt = &th["stats"]["control"]["targets"][0];
    assert_eq!(tt["settings"]["attraction"].as_f64(), Some(0.0));
    assert_eq!(tt["settings"]["velocity"].as_f64(), Some(0.0));
    assert_eq!(tt["settings"]["motion"], "frames");
    let fill = |s: &serde_json::Value| {
        s["stats"]["control"]["targets"][0]["last"]["fill"]
            .as_f64()
            .unwrap()
    };
    assert!(
        fill(&s) > fill(&th),
        "fidelity {} against thesis {}",
        fill(&s),
        fill(&th)
    );
}

/// A finer spacing: more particles, mass rho0 s^3, h and the step scaled.
#[test]
fn the_spacing_switch_scales_the_fluid() {
    let dir = tempfile::tempdir().unwrap();
    let fine = run(dir.path(), "fine", "1", &["--fluid", "spacing=0.02"]);
    let coarse = run(dir.path(), "coarse", "1", &[]);
    let n = |s: &serde_json::Value| s["stats"]["particles"].as_f64().unwrap();
    let f = &fine["config"]["fluid"];
    let m = f["mass"].as_f64().unwrap();
    assert!((m - 998.29 * 0.02f64.powi(3)).abs() < 1e-6, "mass {m}");
    let h = f["h"].as_f64().unwrap();
    assert!(
        (h / 0.02 - 0.0457 / (0.02f64 / 998.29).cbrt()).abs() < 1e-3,
        "h {h}"
    );
    // The pool ([pool]: 1.3 x the walker's volume) holds the same water at either spacing:
    // particles x spacing cubed agree to within a lattice layer of its depth.
    let sc = coarse["config"]["fluid"]["spacing"].as_f64().unwrap();
    assert!(
        sc > 0.021,
        "the default spacing chosen for the walker: {sc}"
    );
    let (vf, vc) = (n(&fine) * 0.02f64.powi(3), n(&coarse) * sc.powi(3));
    assert!(
        (vf / vc - 1.0).abs() < 0.15,
        "pool water {vf} m^3 at spacing 0.02 against {vc} at {sc}"
    );
    assert!(n(&fine) > n(&coarse));
    let steps = |s: &serde_json::Value| s["stats"]["steps"].as_u64().unwrap();
    assert!(
        steps(&fine) > steps(&coarse),
        "more steps per frame at a finer spacing"
    );
}

/// Dual quaternions skin the control particles too.
#[test]
fn dqs_skins_the_control_particles() {
    let dir = tempfile::tempdir().unwrap();
    let dqs = run(dir.path(), "dqs", "2", &["--skinning", "dqs"]);
    assert!(
        dqs["stats"]["control"]["targets"][0]["control_particles"]
            .as_u64()
            .unwrap()
            > 500
    );
}

#[test]
fn bad_fidelity_input_fails_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bad");
    let o = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["--fluid", "spacing=-1"], "spacing must be positive"),
        (
            vec!["--control-attraction=-2"],
            "--control-attraction must be at least 0",
        ),
        (
            vec!["--control-reach", "5"],
            "--control-reach must be positive and at most",
        ),
        (
            vec!["--placement", "rays", "--control-damping", "2"],
            "need control particles that persist",
        ),
    ] {
        let mut a = vec![
            "run",
            "--scene",
            "character",
            "--frames",
            "1",
            "--render",
            "points",
            "--quiet",
            "--out",
            o,
        ];
        a.extend_from_slice(&args);
        let r = fluidform(&a);
        let t = text(&r);
        assert!(!r.status.success() && t.contains(needle), "{args:?}: {t}");
        assert_eq!(t.trim().lines().count(), 1, "{t}");
    }
}

#[test]
fn inspect_reports_the_thinnest_part() {
    let o = fluidform(&["inspect", "builtin:walker", "--json"]);
    assert!(o.status.success(), "{}", text(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let t = &j["thinnest"];
    let d = t["diameter"].as_f64().unwrap();
    assert!(d > 0.01 && d < 0.2, "{t}");
    assert!((t["spacing_for_three"].as_f64().unwrap() - d / 3.0).abs() < 1e-6);
    let s0 = (0.02f64 / 998.29).cbrt();
    assert!((t["spacings_at_default"].as_f64().unwrap() - d / s0).abs() < 1e-3);
}
