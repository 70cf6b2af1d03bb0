//! Liquid characters end to end: a capsule target fills, group-only control leaves the
//! other group alone, the time step does not change the outcome, the built-in scene runs
//! with validation, and bad control input is a clear error.
use fluidform::run::{run, RunOptions, RunStats};
use std::path::Path;
mod common;
use common::{fluidform, summary, text};

/// A pool (group 0) under a capsule target, and a second pool (group 1) far to the side
/// (1 m apart: neither pool's spreading reaches the other in the tests' times; checked).
fn scene(dir: &Path, name: &str, control: &str, dt: f32, substeps: u32) -> String {
    let text = format!(
        r#"
name = "{name}"
frames = 60
[domain]
min = [-0.3, 0.0, -0.15]
max = [1.3, 0.6, 0.15]
[fluid]
eos = "tait"
sound_speed = 20.0
clamp_negative_pressure = true
dt = {dt}
substeps = {substeps}
[[blocks]]
min = [-0.15, 0.0, -0.15]
max = [0.15, 0.1, 0.15]
group = 0
[[blocks]]
min = [1.15, 0.0, -0.15]
max = [1.3, 0.1, 0.15]
group = 1
[camera]
eye = [0.15, 0.4, 1.6]
target = [0.15, 0.15, 0.0]
[character]
file = "builtin:capsule"
position = [0.0, 0.0, 0.0]
{control}
"#
    );
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

fn play(path: &str, out: &Path, frames: u64, extra: &[&str]) -> fluidform::run::RunResult {
    use clap::Parser;
    #[derive(Parser)]
    struct Only {
        #[command(flatten)]
        s: fluidform::config::Switches,
    }
    let mut args = vec![
        "t",
        "--render",
        "points",
        "--width",
        "64",
        "--height",
        "64",
        "--quiet",
        "--validation",
    ];
    args.extend_from_slice(extra);
    let switches = Only::parse_from(args).s;
    run(&RunOptions {
        scene: path.into(),
        frames: Some(frames),
        out: out.into(),
        save_every: 0,
        switches,
    })
    .unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn control_of(r: &fluidform::run::RunResult) -> fluidform::control::metrics::ControlStats {
    match &r.summary.stats {
        RunStats::Sph(s) => s.control.clone().expect("stats.control").targets[0].clone(),
        _ => panic!("not an SPH run"),
    }
}

/// A ball of water high inside a capsule target, released at 0.2 s: until then the control
/// slows its fall; after it, its centre of mass falls freely.
#[test]
fn release_returns_the_fluid_to_free_fall() {
    let dir = tempfile::tempdir().unwrap();
    let text = r#"
name = "release"
[domain]
min = [-0.3, 0.0, -0.3]
max = [0.3, 1.2, 0.3]
[fluid]
eos = "tait"
sound_speed = 20.0
clamp_negative_pressure = true
dt = 0.0009
substeps = 12
[[balls]]
center = [0.0, 0.78, 0.0]
radius = 0.07
[character]
file = "builtin:capsule"
position = [0.0, 0.6, 0.0]
[control]
adaptive = "on"
[[timeline]]
time = 0.0
action = "attach"
target = "character"
[[timeline]]
time = 0.2
action = "release"
fade = 0.0
"#;
    let path = dir.path().join("release.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.path().join("out");
    let r = play(
        path.to_str().unwrap(),
        &out,
        28,
        &["--export", "ply", "--export-every", "1"],
    );
    let RunStats::Sph(st) = &r.summary.stats else {
        panic!("not an SPH run")
    };
    let c = st.control.clone().unwrap();
    assert_eq!(c.events.len(), 2, "{:?}", c.events);
    let released = c.events[1].frame as usize;
    let frame_time = st.simulated_seconds / 28.0;
    assert!(
        (c.events[1].time - 0.2).abs() <= frame_time,
        "released at {}",
        c.events[1].time
    );
    let com = |f: usize| {
        let ps = read_ply(&r.exports[f]);
        ps.iter().map(|(_, p)| p[1] as f64).sum::<f64>() / ps.len() as f64
    };
    // Attached: the control slows the fall (the ball, a quarter of the capsule's volume,
    // spreads into its lower part), far short of the free fall's 0.2 m by 0.2 s.
    let t0 = (released - 1) as f64 * frame_time + frame_time;
    let fell = 0.78 - com(released - 1);
    assert!(
        fell < 0.75 * 0.5 * 9.81 * t0 * t0,
        "fell {fell} m in {t0} s while attached"
    );
    let text = std::fs::read_to_string(out.join("control.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "inside_fraction").unwrap();
    let rows: Vec<Vec<String>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let inside: f64 = rows.last().unwrap()[col].parse().unwrap();
    assert!(inside > 0.9, "inside fraction {inside} when released");
    // Released: y'' = -g (second differences 3 frames apart, before the first drops
    // thrown out while attached reach the floor).
    let (a, b, d) = (com(released + 1), com(released + 4), com(released + 7));
    let dt = 3.0 * frame_time;
    let acc = (d - 2.0 * b + a) / (dt * dt);
    assert!(
        (acc + 9.81).abs() < 0.05 * 9.81,
        "centre of mass acceleration {acc} m/s^2 after release"
    );
    // The control records no passes once released: its metric rows stop.
    let csv = std::fs::read_to_string(out.join("control.csv")).unwrap();
    assert_eq!(csv.lines().count() - 1, released, "{csv}");
}

/// Rays re-place the capsule's particles every frame (its surface has fewer vertices
/// than the particles' capacity: nothing copies by the vertex count).
#[test]
fn rays_fill_the_capsule_frame_after_frame() {
    let dir = tempfile::tempdir().unwrap();
    // (c_cp scaled by the spacing cubed: eq. 7 sums over every control particle.)
    let control = "[control]\nplacement = \"rays\"\nspacing = 0.015\npressure = 1e-4";
    let path = scene(dir.path(), "rays", control, 9e-4, 12);
    let r = play(&path, &dir.path().join("out"), 30, &[]);
    let c = control_of(&r);
    assert_eq!(c.placement, Some(fluidform::config::Placement::Rays));
    // The capsule's lattice: about its volume (0.0061 m^3) over spacing^3, 1800.
    let n = c.control_particles;
    assert!((1500..2100).contains(&n), "{n} control particles");
    let last = c.last.unwrap();
    assert!(
        last.coverage > 0.2,
        "coverage {} after 30 frames",
        last.coverage
    );
}

/// Timelines that cannot play are refused when the scene loads, with the event named.
#[test]
fn bad_timelines_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let base = scene(dir.path(), "tl", "[control]", 9e-4, 12);
    let base = std::fs::read_to_string(base).unwrap();
    let cases = [
        ("time = -1.0\naction = \"attach\"\ntarget = \"character\"", "time must be at least 0"),
        ("time = 0.0\naction = \"attach\"\ntarget = \"nobody\"", "no control target named 'nobody'"),
        ("time = 0.0\naction = \"union\"\ntarget = \"character\"", "use attach"),
        ("time = 0.0\naction = \"release\"", "release with no target attached"),
        ("time = 0.0\naction = \"attach\"\ntarget = \"character\"\n[[timeline]]\ntime = 1.0\naction = \"attach\"\ntarget = \"character\"", "already attached"),
        ("time = 0.0\naction = \"fly\"", "unknown variant"),
    ];
    for (i, (event, needle)) in cases.iter().enumerate() {
        let p = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&p, format!("{base}\n[[timeline]]\n{event}\n")).unwrap();
        let e = fluidform::scene::Scene::load(p.to_str().unwrap())
            .err()
            .unwrap_or_else(|| panic!("case {i} loaded"))
            .to_string();
        assert!(
            e.contains(needle) && e.lines().count() == 1,
            "case {i}: {e}"
        );
    }
}

#[test]
fn a_capsule_fills_and_the_time_step_does_not_matter() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = scene(
        d,
        "fill",
        "[control]\nadaptive = \"on\"\ngroup = 0",
        9e-4,
        12,
    );
    let r = play(&path, &d.join("a"), 90, &[]);
    let c = control_of(&r);
    let last = c.last.clone().unwrap();
    assert!(
        last.coverage >= 0.8,
        "coverage {} after 90 frames",
        last.coverage
    );
    assert!(c.control_particles > 100);
    assert!(
        last.density_ratio_max < 1.5,
        "compressed to {}",
        last.density_ratio_max
    );
    let csv = std::fs::read_to_string(d.join("a/control.csv")).unwrap();
    assert_eq!(csv.lines().count(), 91, "a header and a row per frame");
    // Half the step, twice the steps: the same simulated time, about the same shape.
    let path = scene(
        d,
        "half",
        "[control]\nadaptive = \"on\"\ngroup = 0",
        4.5e-4,
        24,
    );
    let half = control_of(&play(&path, &d.join("b"), 90, &[]))
        .last
        .unwrap();
    assert!(
        (half.coverage - last.coverage).abs() < 0.1,
        "coverage {} vs {}",
        half.coverage,
        last.coverage
    );
    assert!(
        (half.inside_fraction - last.inside_fraction).abs() < 0.1,
        "inside fraction {} vs {}",
        half.inside_fraction,
        last.inside_fraction
    );
}

#[test]
fn group_only_control_leaves_the_other_group_alone() {
    group_only_control(&[]);
}

/// The control force and groups with each incompressible solver: 6 fixed steps of 1.8 ms
/// per frame and 8 iterations per solve. A solve stops on the mean error over every
/// particle and CFL steps follow the fastest one, so group 0's control would change group
/// 1's steps and iterations, and its settling splash with them; fixed, group 1 must match
/// the free run as a body (see group_only_control).
#[test]
fn control_and_groups_work_with_every_solver() {
    for solver in ["pcisph", "dfsph", "pbf"] {
        eprintln!("solver {solver}");
        group_only_control(&[
            "--solver",
            solver,
            "--fluid",
            "dt=0.0018",
            "--fluid",
            "substeps=6",
            "--fluid",
            "min_iterations=8",
            "--fluid",
            "max_iterations=8",
            "--fluid",
            "pbf_iterations=8",
        ]);
    }
}

/// Control on group 0 raises it into the target and leaves group 1 where an uncontrolled
/// run leaves it. `solver`: extra switches (the solver and its step).
fn group_only_control(solver: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let free = scene(d, "free", "", 9e-4, 12);
    let held = scene(d, "held", "[control]\ngroup = 0", 9e-4, 12);
    let frames = 20;
    // Both at the default spacing (a controlled scene would otherwise choose its own
    // from the character: scene::fit).
    let spacing = fluidform::sph::params::FluidParams::default().spacing();
    let spacing_switch = format!("spacing={spacing}");
    let mut ex = vec![
        "--export",
        "ply",
        "--export-every",
        "19",
        "--fluid",
        &spacing_switch,
    ];
    ex.extend_from_slice(solver);
    let a = play(&free, &d.join("free"), frames, &ex);
    let b = play(&held, &d.join("held"), frames, &ex);
    let again = play(&free, &d.join("again"), frames, &ex);
    // The steps and the iterations of each solve are the same (they are fixed here).
    let steps = |name: &str| -> Vec<String> {
        std::fs::read_to_string(d.join(name).join("steps.csv"))
            .unwrap()
            .lines()
            .map(|l| {
                let c: Vec<&str> = l.split(',').collect();
                format!("{} {} {}", c[3], c[4], c[7])
            })
            .collect()
    };
    assert_eq!(steps("free"), steps("held"), "steps or iterations differ");
    let read = |r: &fluidform::run::RunResult| -> Vec<(u32, [f32; 3])> {
        let p = r.exports.last().expect("an export").clone();
        read_ply(&p)
    };
    // Every comparison below is of bodies (extents, centroid, spread): particle order
    // does not matter.
    let (pa, pb) = (read(&a), read(&b));
    let g1 = |v: &[(u32, [f32; 3])]| {
        v.iter()
            .filter(|x| x.0 == 1)
            .map(|x| x.1)
            .collect::<Vec<_>>()
    };
    let pc = read(&again);
    let (fa, fb, fc) = (g1(&pa), g1(&pb), g1(&pc));
    assert_eq!(fa.len(), fb.len());
    // The premise: the free groups never meet (else control of one rightly moves the other).
    let reach = |v: &[(u32, [f32; 3])], g: u32| {
        let x = v.iter().filter(|x| x.0 == g).map(|x| x.1[0]);
        (
            x.clone().fold(f32::MAX, f32::min),
            x.fold(f32::MIN, f32::max),
        )
    };
    let gap = reach(&pa, 1).0 - reach(&pa, 0).1;
    assert!(
        gap > 0.1,
        "the free groups came within {gap} m of each other"
    );
    // The groups never meet, so group 1 feels group 0's control only through what is
    // global: the steps and iterations (fixed here) and the order of float sums. Group 0's
    // new cells shift group 1's sorted slots across workgroups, which reorders the
    // atomics of the counting sort within a cell and so the sums; the splash amplifies
    // that to centimetres for a few particles (seen: 4 mm with DFSPH here, 18 cm with
    // PCISPH on CI). What control must not change is group 1 as a body: its centroid and
    // spread stay within a tenth of a spacing of the free run's.
    let body = |v: &[[f32; 3]]| {
        let n = v.len() as f64;
        let c: Vec<f64> = (0..3)
            .map(|k| v.iter().map(|x| x[k] as f64).sum::<f64>() / n)
            .collect();
        let spread = (v
            .iter()
            .map(|x| (0..3).map(|k| (x[k] as f64 - c[k]).powi(2)).sum::<f64>())
            .sum::<f64>()
            / n)
            .sqrt();
        (c, spread)
    };
    let tol = 0.1 * spacing as f64;
    let ((ca, sa), (cb, sb), (cc, sc)) = (body(&fa), body(&fb), body(&fc));
    let shift = |u: &[f64], v: &[f64]| (0..3).map(|k| (u[k] - v[k]).abs()).fold(0.0, f64::max);
    eprintln!(
        "group 1: centroid moved {:.2e} m under control ({:.2e} m between free runs), spread {sa:.4} vs {sb:.4} m",
        shift(&ca, &cb),
        shift(&ca, &cc)
    );
    assert!(
        shift(&ca, &cc) <= tol && (sa - sc).abs() <= tol,
        "two free runs differ as bodies"
    );
    assert!(
        shift(&ca, &cb) <= tol,
        "group 1's centroid moved by {} m under group 0's control",
        shift(&ca, &cb)
    );
    assert!(
        (sa - sb).abs() <= tol,
        "group 1's spread changed from {sa} to {sb} m under group 0's control"
    );
    // Group 0 did feel the control.
    let g0 = |v: &[(u32, [f32; 3])]| {
        v.iter()
            .filter(|x| x.0 == 0)
            .map(|x| x.1[1])
            .fold(0.0, f32::max)
    };
    assert!(
        g0(&pb) > g0(&pa) + 0.02,
        "controlled group rose: {} vs {}",
        g0(&pb),
        g0(&pa)
    );
}

#[test]
fn the_character_scene_runs_and_bad_control_input_fails_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c");
    let out_s = out.to_str().unwrap();
    let o = fluidform(&[
        "run",
        "--scene",
        "character",
        "--frames",
        "3",
        "--width",
        "64",
        "--height",
        "64",
        "--quiet",
        "--validation",
        "--out",
        out_s,
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    for scope in [
        "sph/control/skin",
        "sph/control/control-density",
        "sph/control/control-force",
    ] {
        assert!(t.contains(scope), "{scope} missing: {t}");
    }
    // Rays re-place every frame in their own scope.
    let rays = dir.path().join("rays");
    let o = fluidform(&[
        "run",
        "--scene",
        "character",
        "--frames",
        "3",
        "--render",
        "points",
        "--placement",
        "rays",
        "--quiet",
        "--validation",
        "--out",
        rays.to_str().unwrap(),
    ]);
    let t = text(&o);
    assert!(o.status.success() && t.contains("sph/control/place"), "{t}");
    let s = summary(&rays);
    let n = s["stats"]["control"]["targets"][0]["control_particles"]
        .as_u64()
        .unwrap();
    assert!(n > 500, "{n} control particles placed by rays");
    assert_eq!(
        std::fs::read_to_string(out.join("control.csv"))
            .unwrap()
            .lines()
            .count(),
        4
    );
    // --particles scales the scene, the character with it.
    let big = dir.path().join("big");
    let o = fluidform(&[
        "run",
        "--scene",
        "character",
        "--frames",
        "1",
        "--render",
        "points",
        "--particles",
        "6000",
        "--quiet",
        "--out",
        big.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let s = summary(&big);
    let h = s["stats"]["character"]["height"].as_f64().unwrap();
    assert!(h > 1.3 && h < 1.7, "the walker grew with the scene: {h} m");
    let fails: [(&[&str], &str); 7] = [
        (
            &["--scene", "character", "--adaptive-thresholds", "1.3,1.2"],
            "0 < low < high",
        ),
        (
            &["--scene", "character", "--adaptive-factors", "2"],
            "--adaptive-factors takes two numbers",
        ),
        (
            &[
                "--scene",
                "character",
                "--placement",
                "rays",
                "--control-velocity",
                "1",
            ],
            "persist between frames",
        ),
        (
            &["--scene", "character", "--control-pressure=-1"],
            "--control-pressure must be at least 0",
        ),
        (
            &["--scene", "character", "--control-every", "0"],
            "--control-every must be in 1..=1000",
        ),
        (
            &["--scene", "drop", "--adaptive", "on"],
            "--adaptive does not apply",
        ),
        (
            &["--scene", "character", "--control-spacing", "5"],
            "no control particles",
        ),
    ];
    for (args, needle) in fails {
        let mut all = vec!["run"];
        all.extend_from_slice(args);
        all.extend(["--frames", "1", "--quiet", "--out", out_s]);
        let o = fluidform(&all);
        let t = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(1), "{args:?}: {t}");
        assert!(
            t.contains(needle) && t.trim().lines().count() == 1,
            "{args:?}: {t}"
        );
    }
}

/// (group, position) of every particle of a fluidform PLY (36 bytes per vertex).
fn read_ply(p: &Path) -> Vec<(u32, [f32; 3])> {
    let bytes = std::fs::read(p).unwrap();
    let end = b"end_header\n";
    let at = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    bytes[at..]
        .chunks_exact(36)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap());
            (
                u32::from_le_bytes(c[32..36].try_into().unwrap()),
                [f(0), f(1), f(2)],
            )
        })
        .collect()
}

#[test]
fn bench_control_reports_every_adaptive_mode() {
    let dir = tempfile::tempdir().unwrap();
    let o = fluidform(&[
        "bench",
        "control",
        "--frames",
        "3",
        "--quiet",
        "--validation",
        "--scene",
        "character",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let md = std::fs::read_to_string(dir.path().join("sweep.md")).unwrap();
    for v in [
        "adaptive-off",
        "adaptive-on",
        "adaptive-smooth",
        "time to 90% s",
        "final coverage",
    ] {
        assert!(md.contains(v), "{v} missing from {md}");
    }
    // Three frames never reach 90%: reported, not invented.
    assert!(md.contains("not in"), "{md}");
}
