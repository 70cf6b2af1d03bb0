//! `run --scopes`: which GPU scopes write timestamps (the frame alone, the frame and the
//! scopes directly in it, or all), with the deeper scopes left out of timings.csv; the
//! benches and experiments, which read every pass, refuse anything but all.
mod common;
use std::collections::BTreeSet;

/// The scope keys of `run --scopes scopes` on the default scene (3 small frames).
fn keys(scopes: &str, dir: &std::path::Path) -> BTreeSet<String> {
    let out = dir.join(scopes);
    let r = common::fluidform(&[
        "run",
        "--scene",
        "character",
        "--frames",
        "3",
        "--width",
        "48",
        "--height",
        "48",
        "--save-every",
        "0",
        "--scopes",
        scopes,
        "--validation",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", common::text(&r));
    let csv = std::fs::read_to_string(out.join("timings.csv")).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().to_string())
        .collect()
}

#[test]
fn scopes_time_the_frame_its_phases_or_every_pass() {
    let dir = tempfile::tempdir().unwrap();
    let frame = keys("frame", dir.path());
    let passes = keys("passes", dir.path());
    let all = keys("all", dir.path());
    assert_eq!(frame, BTreeSet::from(["frame".to_string()]));
    // The frame's phases: sph, render and the metrics, not the passes inside them.
    for k in ["frame", "sph", "render", "control-metrics"] {
        assert!(passes.contains(k) && all.contains(k), "{k}: {passes:?}");
    }
    for k in ["render/march", "sph/density", "sph/arrange/sort"] {
        assert!(!passes.contains(k) && all.contains(k), "{k}: {all:?}");
    }
    assert!(passes.is_subset(&all));
    for what in [&["bench", "render"][..], &["experiment", "table2"][..]] {
        let mut args = what.to_vec();
        args.extend(["--scopes", "passes"]);
        let r = common::fluidform(&args);
        assert!(!r.status.success());
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains("--scopes passes belongs to run"), "{err}");
    }
}
