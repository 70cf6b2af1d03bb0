//! Bad scene input, the memory bound, particle export and timings against bench.

use super::*;

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
/// per particle (every buffer but the pixel-sized ones and those sized by the metaballs'
/// screen coverage, which grow on overflow: the lists, and the compute build's tile pairs).
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
        "render",
        "sbuffer",
        "abuffer",
        "sky",
        "frame",
        "color",
        "depth",
        "tile ranges",
        "tile pair",
        "tile metaballs",
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
        // Within 3x: two separate runs on a shared CPU differ by up to 1.5x (measured),
        // 2.08x with other work on the machine (2026-11-28); the misattribution this
        // guards against was 100x (0.02 against 3 ms).
        assert!(
            (1.0 / 3.0..=3.0).contains(&ratio),
            "{pass}: run {ran:.3} ms per step, bench {bench:.3} ms (ratio {ratio:.2})"
        );
    }
}

/// A frame the device cannot hold is refused at start, naming the largest frame of its
/// shape that fits (a new user's --width 16384 --height 16384 on the demo ran minutes in
/// silence). On lavapipe, as every test here: its 128 MiB storage binding range and 2 GiB
/// heap refuse 16384 x 8192 (a GPU with 4 GiB bindings would render it).
#[test]
fn a_frame_too_large_is_refused_with_the_size_that_fits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let run = |w: &str, h: &str| {
        let t = std::time::Instant::now();
        let o = fluidform(&[
            "run",
            "--scene",
            "demo",
            "--out",
            d,
            "--frames",
            "1",
            "--save-every",
            "0",
            "--width",
            w,
            "--height",
            h,
        ]);
        (o, t.elapsed().as_secs_f64())
    };
    let (o, secs) = run("16384", "8192");
    assert!(!o.status.success());
    let t = text(&o);
    assert!(t.contains("a 16384 x 8192 frame is too large"), "{t}");
    assert!(secs < 20.0, "took {secs} s");
    // "... --width W --height H" at the end of the one error line.
    let line = t.lines().find(|l| l.contains("too large")).unwrap();
    let nums: Vec<u32> = line
        .split("--width ")
        .nth(1)
        .unwrap()
        .split(" --height ")
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let (w, h) = (nums[0], nums[1]);
    assert!(w < 16384 && h < 8192 && w >= 64, "{w} x {h}");
    assert!(
        (w as f64 / h as f64 - 2.0).abs() < 0.01,
        "shape kept: {w} x {h}"
    );
}
