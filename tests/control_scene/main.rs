//! Liquid characters end to end: a capsule target fills, group-only control leaves the
//! other group alone, the time step does not change the outcome, the built-in scene runs
//! with validation, and bad control input is a clear error.
use fluidform::run::{run, RunOptions, RunStats};
use std::path::Path;
#[path = "../common/mod.rs"]
mod common;
use common::{fluidform, summary, text};

mod character;
mod groups;

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
    assert_eq!(c.placement, Some(fluidform::control::Placement::Rays));
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
