//! SPH scenes end to end, scene files, bench smoke, the step limit, fluid overrides, sync hazards.

use super::*;

#[test]
fn run_sph_scenes_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    for (scene, neighbors, render) in [
        ("dam-break", "grid", "metaballs"),
        ("drop", "hash", "metaballs"),
        ("resting-block", "morton", "points"),
    ] {
        let out = dir.path().join(scene);
        let o = fluidform(&[
            "run",
            "--scene",
            scene,
            "--particles",
            "1500",
            "--frames",
            "2",
            "--out",
            out.to_str().unwrap(),
            "--validation",
            "--width",
            "96",
            "--height",
            "64",
            "--neighbors",
            neighbors,
            "--render",
            render,
        ]);
        assert!(o.status.success(), "{scene}: {}", text(&o));
        assert!(out.join("frame_0001.png").exists());
        let s = summary(&out);
        assert_eq!(s["validation"]["errors"], 0);
        assert_eq!(s["stats"]["nan"], 0, "{scene}");
        assert_eq!(s["stats"]["outside_domain"], 0, "{scene}");
        assert!(s["stats"]["steps"].as_u64().unwrap() >= 2);
        let rho = s["stats"]["density_mean_over_rest"].as_f64().unwrap();
        assert!(
            rho > 0.5 && rho < 1.5,
            "{scene}: mean density / rho0 = {rho}"
        );
        let passes: Vec<&str> = if render == "metaballs" {
            vec![
                "sph/arrange",
                "sph/arrange/sort",
                "sph/density",
                "sph/forces",
                "sph/integrate",
                "render/bounds",
                "render/count",
                "render/scan",
                "render/fill",
                "render/march",
            ]
        } else {
            vec![
                "sph/arrange",
                "sph/density",
                "sph/forces",
                "sph/integrate",
                "points",
            ]
        };
        for pass in passes {
            assert!(
                s["pass_ms"][pass]["median"].as_f64().is_some(),
                "{scene}: pass {pass}"
            );
        }
        assert_eq!(s["stats"]["render"]["renderer"], render);
        if render == "metaballs" {
            assert!(s["stats"]["render"]["max_fragments"].as_u64().unwrap() > 0);
        }
        assert_eq!(s["config"]["neighbors"], neighbors);
    }
}

#[test]
fn run_scene_file_with_colliders() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/scenes/obstacles.toml");
    let s = run_ok(dir.path(), &["--scene", scene, "--frames", "3"]);
    assert_eq!(s["config"]["scene"], "obstacles");
    assert_eq!(s["stats"]["outside_domain"], 0);
    assert!(
        !dir.path().join("frame_0000.png").exists(),
        "--save-every 0 saves no frames"
    );
}

#[test]
fn bench_smoke_writes_sweep_tables() {
    let dir = tempfile::tempdir().unwrap();
    for (what, extra) in [
        ("scan", vec![]),
        ("sort", vec![]),
        ("neighbors", vec!["--neighbors", "hash"]),
        ("sph", vec!["--neighbors", "grid"]),
    ] {
        let out = dir.path().join(what);
        let mut args = vec![
            "bench",
            what,
            "--particles",
            "3000",
            "--frames",
            "3",
            "--warmup",
            "1",
            "--validation",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = fluidform(&args);
        assert!(o.status.success(), "{what}: {}", text(&o));
        let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
        let rows: Vec<&str> = csv.lines().collect();
        assert!(
            rows[0].starts_with("variant,n,reps,median_ms"),
            "{what}: {}",
            rows[0]
        );
        assert!(rows.len() >= 2, "{what}: no rows");
        for r in &rows[1..] {
            let cols: Vec<&str> = r.split(',').collect();
            // --frames 3 spread over the protocol's 5 rounds: at least one a round.
            assert_eq!(cols[2], "5", "{what}: reps");
            let ms: f64 = cols[3].parse().unwrap();
            assert!(ms > 0.0 && ms.is_finite(), "{what}: {r}");
        }
        let md = std::fs::read_to_string(out.join("sweep.md")).unwrap();
        assert!(md.contains("| variant | N | reps |"), "{what}");
        // The plot beside the table: a real image, not blank.
        let img = image::open(out.join("sweep.png"))
            .unwrap_or_else(|e| panic!("{what}: sweep.png: {e}"))
            .to_rgb8();
        assert_eq!(img.dimensions(), (900, 560), "{what}");
        let coloured = img
            .pixels()
            .filter(|p| p[0] != p[1] || p[1] != p[2])
            .count();
        assert!(coloured > 500, "{what}: only {coloured} coloured pixels");
        // `fluidform plot` draws the same table from its CSV.
        let png = out.join("again.png");
        let o = fluidform(&[
            "plot",
            out.join("sweep.csv").to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
            "--title",
            what,
            "--scope",
            what,
            "--device",
            "lavapipe",
            "--date",
            "2026-01-01",
        ]);
        assert!(o.status.success(), "{}", text(&o));
        assert_eq!(image::open(&png).unwrap().width(), 900);
        let runs: Vec<_> = std::fs::read_dir(out.join("runs")).unwrap().collect();
        assert_eq!(runs.len(), rows.len() - 1, "{what}: one summary per row");
    }
}

#[test]
fn cfl_limits_the_step_and_keeps_the_frame_time() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/scenes/cfl.toml");
    let s = run_ok(dir.path(), &["--scene", scene]);
    assert_eq!(s["frames"], 3);
    // Steps of 9.14e-4 s while every speed stays below c, never snapped to the frame: about
    // 11 a frame, the simulated time within one step of the frames' 0.03 s (the rest carries).
    let steps = s["stats"]["steps"].as_u64().unwrap();
    assert!((32..=34).contains(&steps), "{}", s["stats"]);
    let t = s["stats"]["simulated_seconds"].as_f64().unwrap();
    assert!((t - 0.03).abs() < 9.2e-4, "simulated {t} s");
}

#[test]
fn fluid_overrides_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let o = fluidform(&[
        "run",
        "--scene",
        "resting-block",
        "--frames",
        "1",
        "--save-every",
        "0",
        "--out",
        d,
        "--fluid",
        "viscosity=1.25",
        "--fluid",
        "eos=tait",
        "--fluid",
        "gravity=[0.0, -1.0, 0.0]",
        // Tait water needs steps far below the scene's 0.01 s: without the CFL limit the
        // run goes unstable in its first frame (and is stopped there).
        "--fluid",
        "cfl=0.4",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let s = summary(dir.path());
    assert_eq!(s["config"]["fluid"]["viscosity"], 1.25);
    assert_eq!(s["config"]["fluid"]["eos"], "tait");
    assert_eq!(s["config"]["fluid"]["gravity"][1], -1.0);
    for (arg, needle) in [
        ("viscsity=1", "unknown field `viscsity`"),
        ("h=-1", "fluid.h must be positive"),
        ("eos=steam", "unknown variant `steam`"),
        ("viscosity", "expected KEY=VALUE"),
    ] {
        let o = fluidform(&[
            "run",
            "--scene",
            "resting-block",
            "--frames",
            "1",
            "--out",
            d,
            "--fluid",
            arg,
        ]);
        assert!(!o.status.success(), "{arg} accepted");
        assert!(text(&o).contains(needle), "{arg}: {}", text(&o));
    }
    let o = fluidform(&[
        "run", "--scene", "orbits", "--frames", "1", "--out", d, "--fluid", "h=1",
    ]);
    assert!(!o.status.success());
    assert!(text(&o).contains("--fluid does not apply"), "{}", text(&o));
}

/// Every scene kind and list mode for two frames with the validation layer's
/// synchronization validation on (`--validation` enables it): any hazard the narrowed
/// barriers let through fails the run. Debian 12's layer (1.3.239) sees hazards between
/// transfers (updates, fills, copies, readbacks) and shaders, not between two dispatches
/// through push descriptors (tests/seams.rs shows what it reports). Typed summaries are
/// read back.
#[test]
fn every_scene_kind_and_list_mode_is_free_of_sync_hazards() {
    use fluidform::run::SphRunStats;
    let dir = tempfile::tempdir().unwrap();
    let small = ["--frames", "2", "--width", "96", "--height", "72"];
    let o = run_ok(
        dir.path(),
        &[&small[..], &["--scene", "orbits", "--particles", "300"]].concat(),
    );
    assert_eq!(o["validation"]["errors"], 0);
    // run's S-buffer is built in compute (no sort pass); the thesis's by raster.
    for (list, extra, build) in [
        ("none", "phong", None),
        ("abuffer", "phong", None),
        ("sbuffer", "phong", Some("raster")),
        ("sbuffer", "glass", Some("raster")),
        ("sbuffer", "glass", None),
    ] {
        let mut args = small.to_vec();
        args.extend([
            "--scene",
            "drop",
            "--particles",
            "600",
            "--list",
            list,
            "--material",
            extra,
        ]);
        args.extend(build.map(|b| ["--build", b]).iter().flatten());
        let s = run_ok(dir.path(), &args);
        assert_eq!(s["validation"]["errors"], 0, "{list} {extra}");
        let stats: SphRunStats = serde_json::from_value(s["stats"].clone()).unwrap();
        assert_eq!((stats.physics.nan, stats.physics.outside_domain), (0, 0));
        assert!(stats.steps >= 2);
        if list != "none" {
            assert!(stats.render.max_fragments > 0, "{list}");
        }
        // Scope keys carry their subsystem: the neighbour sort and the list sort never merge.
        let keys: Vec<&String> = s["pass_ms"].as_object().unwrap().keys().collect();
        assert!(keys.iter().any(|k| *k == "sph/arrange/sort"), "{keys:?}");
        assert_eq!(
            keys.iter().any(|k| *k == "render/sort"),
            extra == "glass" && list == "sbuffer" && build == Some("raster")
        );
        assert_eq!(
            keys.iter().any(|k| *k == "render/pair sort"),
            list == "sbuffer" && build.is_none()
        );
        assert!(!keys.iter().any(|k| *k == "sort"), "{keys:?}");
    }
    let mut args = small.to_vec();
    args.extend([
        "--scene",
        "drop",
        "--particles",
        "600",
        "--render",
        "points",
    ]);
    let s = run_ok(dir.path(), &args);
    assert_eq!(s["validation"]["errors"], 0);
}
