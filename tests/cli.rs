//! The command line end to end: devices, run, and clear errors with non-zero exits.
mod common;
use common::{fluidform, summary, text};

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
    assert_eq!(lines.next(), Some("frame,pass,ms"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    for pass in ["frame", "simulate", "points", "readback"] {
        let n = rows.iter().filter(|r| r[1] == pass).count();
        assert_eq!(n, 3, "pass {pass} rows");
    }
    for r in &rows {
        let ms: f64 = r[2].parse().unwrap();
        assert!(ms >= 0.0 && ms.is_finite());
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
            assert_eq!(cols[2], "3", "{what}: reps");
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
    // ceil(0.01 / 9.14e-4) = 11 steps per frame while every speed stays below c.
    assert_eq!(s["stats"]["steps"], 33, "{}", s["stats"]);
    let t = s["stats"]["simulated_seconds"].as_f64().unwrap();
    assert!((t - 0.03).abs() < 1e-6, "simulated {t} s");
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
    for (list, extra) in [
        ("none", "phong"),
        ("abuffer", "phong"),
        ("sbuffer", "phong"),
        ("sbuffer", "glass"),
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
            extra == "glass" && list == "sbuffer"
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

/// Bad scene input is refused before any allocation (or stopped within a frame), each with
/// a one-line error and a non-zero exit, never an abort, a hang or exit 0 with nonsense.
#[test]
fn bad_scene_input_is_refused_quickly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let timed = |args: &[&str]| {
        let t = std::time::Instant::now();
        let o = fluidform(args);
        (o, t.elapsed().as_secs_f64())
    };
    // About 6e11 particles: refused from the estimate, before any is made.
    let (o, secs) = timed(&["run", "--out", d, "--frames", "1", "--fluid", "mass=1e-9"]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(
        t.contains("implies about") && t.contains("at most 67108864"),
        "{t}"
    );
    assert!(secs < 20.0, "took {secs} s");
    // A huge step goes unstable in the first frame and is stopped there.
    let (o, _) = timed(&[
        "run",
        "--out",
        d,
        "--frames",
        "50",
        "--save-every",
        "0",
        "--fluid",
        "dt=1e9",
        "--width",
        "64",
        "--height",
        "48",
    ]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(t.contains("went unstable: frame 0:"), "{t}");
    // Fluid outside the domain is an error, not silently dropped particles.
    let scene = dir.path().join("outside.toml");
    std::fs::write(
        &scene,
        "name = \"outside\"\n[domain]\nmin = [0, 0, 0]\nmax = [0.2, 0.2, 0.2]\n\
         [[blocks]]\nmin = [-1, -1, -1]\nmax = [5, 5, 5]\n",
    )
    .unwrap();
    let (o, _) = timed(&[
        "run",
        "--out",
        d,
        "--frames",
        "1",
        "--scene",
        scene.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("reaches outside the domain"),
        "{}",
        text(&o)
    );
}

/// BYTES_PER_PARTICLE, used to refuse scenes that cannot fit, bounds what a run allocates
/// per particle (every buffer but the pixel-sized ones).
#[test]
fn bytes_per_particle_bounds_the_allocation() {
    let dir = tempfile::tempdir().unwrap();
    let s = run_ok(
        dir.path(),
        &[
            "--scene", "drop", "--frames", "1", "--width", "64", "--height", "48",
        ],
    );
    let n = s["stats"]["particles"].as_u64().unwrap();
    let pixel_sized = [
        "render", "sbuffer", "abuffer", "sky", "frame", "color", "depth",
    ];
    let per_particle: u64 = s["memory_bytes"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(k, _)| !pixel_sized.iter().any(|p| k.starts_with(p)))
        .map(|(_, v)| v.as_u64().unwrap())
        .sum();
    let bound = fluidform::sph::solver::BYTES_PER_PARTICLE * n;
    assert!(
        per_particle <= bound,
        "{per_particle} bytes for {n} particles > {bound}"
    );
    assert!(
        per_particle * 2 > bound,
        "the bound is loose: {per_particle} of {bound}"
    );
}

/// `--export ply|vtk` writes files ParaView, Blender and splashsurf read: read back here.
#[test]
fn particle_export_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let base = [
        "--scene", "drop", "--frames", "3", "--width", "64", "--height", "48",
    ];
    // Binary little-endian PLY.
    let ply_dir = dir.path().join("ply");
    let s = run_ok(&ply_dir, &[&base[..], &["--export", "ply"]].concat());
    let n = s["stats"]["particles"].as_u64().unwrap() as usize;
    let bytes = std::fs::read(ply_dir.join("particles_0002.ply")).unwrap();
    let end = b"end_header\n";
    let at = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    let header = std::str::from_utf8(&bytes[..at]).unwrap();
    assert!(
        header.starts_with("ply\nformat binary_little_endian 1.0\n"),
        "{header}"
    );
    assert!(
        header.contains(&format!("element vertex {n}\n")),
        "{header}"
    );
    assert_eq!(
        bytes.len() - at,
        n * 36,
        "9 four-byte properties per particle"
    );
    let rec = |i: usize, k: usize| {
        let o = at + i * 36 + k * 4;
        <[u8; 4]>::try_from(&bytes[o..o + 4]).unwrap()
    };
    let mut groups = std::collections::BTreeSet::new();
    for i in 0..n {
        let p: Vec<f32> = (0..3).map(|k| f32::from_le_bytes(rec(i, k))).collect();
        assert!(
            p.iter().all(|x| (0.0..=1.0).contains(x)),
            "particle {i} at {p:?}"
        );
        assert!(f32::from_le_bytes(rec(i, 6)) > 0.0, "density of {i}");
        groups.insert(u32::from_le_bytes(rec(i, 8)));
    }
    assert_eq!(
        groups.into_iter().collect::<Vec<_>>(),
        [0, 1],
        "pool and ball groups"
    );
    // particles.csv: one row per exported frame.
    let csv = std::fs::read_to_string(ply_dir.join("particles.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 3);
    for r in &rows {
        assert_eq!(r.split(',').nth(2).unwrap(), n.to_string());
    }
    // Legacy VTK, big-endian: the points, then the point data in order.
    let vtk_dir = dir.path().join("vtk");
    run_ok(
        &vtk_dir,
        &[&base[..], &["--export", "vtk", "--export-every", "2"]].concat(),
    );
    assert!(
        !vtk_dir.join("particles_0001.vtk").exists(),
        "every second frame only"
    );
    let bytes = std::fs::read(vtk_dir.join("particles_0002.vtk")).unwrap();
    let find = |s: &str| {
        bytes
            .windows(s.len())
            .position(|w| w == s.as_bytes())
            .unwrap()
            + s.len()
    };
    let pts = find(&format!("POINTS {n} float\n"));
    let first: Vec<f32> = (0..3)
        .map(|k| f32::from_be_bytes(bytes[pts + 4 * k..pts + 4 * k + 4].try_into().unwrap()))
        .collect();
    assert!(first.iter().all(|x| (0.0..=1.0).contains(x)), "{first:?}");
    let dens = find("SCALARS density float 1\nLOOKUP_TABLE default\n");
    let rho = f32::from_be_bytes(bytes[dens..dens + 4].try_into().unwrap());
    assert!(rho > 100.0 && rho < 5000.0, "density {rho}");
    let grp = find("SCALARS group int 1\nLOOKUP_TABLE default\n");
    assert_eq!(bytes.len() - grp, n * 4 + 1);
}

/// `run`'s per-pass times are right on lavapipe too, drawing and all: per step they agree
/// with `bench sph` for the same scene, N and neighbour search (medians within 1.5x).
#[test]
fn run_pass_times_agree_with_bench() {
    let dir = tempfile::tempdir().unwrap();
    let n = "6000";
    let run = run_ok(
        &dir.path().join("run"),
        &[
            "--scene",
            "dam-break",
            "--particles",
            n,
            "--frames",
            "10",
            "--render",
            "points",
            "--width",
            "96",
            "--height",
            "72",
            "--neighbors",
            "grid",
        ],
    );
    let steps_per_frame = run["config"]["fluid"]["substeps"].as_f64().unwrap();
    let bench_dir = dir.path().join("bench");
    let o = fluidform(&[
        "bench",
        "sph",
        "--particles",
        n,
        "--neighbors",
        "grid",
        "--frames",
        "10",
        "--warmup",
        "2",
        "--quiet",
        "--out",
        bench_dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let csv = std::fs::read_to_string(bench_dir.join("sweep.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    for pass in ["sph/density", "sph/forces", "sph"] {
        let col = head
            .iter()
            .position(|h| *h == format!("{pass}_ms"))
            .unwrap();
        let bench: f64 = row[col].parse().unwrap();
        let ran = run["pass_ms"][pass]["median"].as_f64().unwrap() / steps_per_frame;
        let ratio = ran / bench;
        // Within 2x: two separate runs on a shared CPU differ by up to 1.5x (measured);
        // the misattribution this guards against was 100x (0.02 against 3 ms).
        assert!(
            (1.0 / 2.0..=2.0).contains(&ratio),
            "{pass}: run {ran:.3} ms per step, bench {bench:.3} ms (ratio {ratio:.2})"
        );
    }
}
