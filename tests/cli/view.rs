//! `fluidform view` under Xvfb on lavapipe: the window's frames are `run`'s (same switches
//! flipped through the command interface the keys use give the same picture), resizing
//! to 1x1 and back and minimising neither crash nor leak, validation stays clean, and
//! without a display it fails with one line saying how to run headless.
use super::common::{fluidform, text};
use std::process::Command;

/// `fluidform view ARGS` on a fresh virtual display.
fn view(args: &[&str]) -> std::process::Output {
    let xvfb = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 800x600x24"])
        .arg(env!("CARGO_BIN_EXE_fluidform"))
        .arg("view")
        .args(args)
        .output();
    xvfb.expect("xvfb-run (run scripts/setup.sh)")
}

fn rgba(path: &std::path::Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

#[test]
fn view_without_a_display_says_how_to_run_headless() {
    let o = Command::new(env!("CARGO_BIN_EXE_fluidform"))
        .args(["view", "--scene", "demo", "--frames", "2"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let t = text(&o);
    assert!(!o.status.success());
    assert_eq!(t.trim().lines().count(), 1, "{t}");
    assert!(t.contains("fluidform run") && t.contains("xvfb-run"), "{t}");
}

/// Six frames of `scene` at 160 x 120 in the window with `flips` (`--at` commands, sent
/// through the interface the keys use) against `run` with `switches`: the golden images'
/// tolerance, 99% of pixels within 4/255. Returns the window's last frame.
fn view_matches_run(
    dir: &std::path::Path,
    scene: &str,
    flips: &[&str],
    switches: &[&str],
) -> image::RgbaImage {
    let shot = dir.join("view.png");
    let size = ["--width", "160", "--height", "120"];
    let mut args = vec![
        "--scene",
        scene,
        "--frames",
        "6",
        "--validation",
        "--hide-panel",
    ];
    args.extend(size);
    for f in flips {
        args.extend(["--at", f]);
    }
    args.extend(["--screenshot", shot.to_str().unwrap()]);
    let o = view(&args);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("view: 6 frames"), "{t}");
    assert!(!t.contains("[vulkan ERROR"), "{t}");
    assert_eq!(t.matches("view rebuilt").count(), flips.len(), "{t}");
    let out = dir.join("run");
    let mut run = vec![
        "run",
        "--scene",
        scene,
        "--frames",
        "6",
        "--validation",
        "--quiet",
    ];
    run.extend(size);
    run.extend(switches);
    run.extend(["--out", out.to_str().unwrap()]);
    let o = fluidform(&run);
    assert!(o.status.success(), "{}", text(&o));
    let (a, b) = (rgba(&shot), rgba(&out.join("frame_0005.png")));
    assert_eq!(a.dimensions(), (160, 120));
    assert_eq!(a.dimensions(), b.dimensions());
    let close = (a.pixels().zip(b.pixels()))
        .filter(|(p, q)| p.0.iter().zip(q.0).all(|(x, y)| x.abs_diff(y) <= 4))
        .count();
    let frac = close as f64 / (160.0 * 120.0);
    assert!(
        frac >= 0.99,
        "{scene} {flips:?}: only {frac:.4} of the pixels agree with run's frame"
    );
    a
}

#[test]
fn view_frames_match_run_after_switch_flips() {
    let dir = tempfile::tempdir().unwrap();
    let flips = ["2:set list abuffer", "3:set density murakami"];
    let switches = ["--list", "abuffer", "--density", "murakami"];
    let a = view_matches_run(dir.path(), "demo", &flips, &switches);
    // The density function changed the picture: the default's frame differs.
    let out2 = dir.path().join("plain");
    let mut plain = vec!["run", "--scene", "demo", "--frames", "6", "--quiet"];
    plain.extend(["--width", "160", "--height", "120"]);
    plain.extend(["--out", out2.to_str().unwrap()]);
    assert!(fluidform(&plain).status.success());
    assert_ne!(rgba(&out2.join("frame_0005.png")).as_raw(), a.as_raw());
}

#[test]
fn view_switches_the_surface_live_as_run_draws_it() {
    let dir = tempfile::tempdir().unwrap();
    view_matches_run(
        dir.path(),
        "drop",
        &["2:set surface mesh"],
        &["--surface", "mesh"],
    );
}

#[test]
fn view_survives_resizing_to_1x1_and_minimising() {
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("after.png");
    let small = dir.path().join("small.png");
    let at_small = format!("5:screenshot {} 64x48", small.display());
    let o = view(&[
        "--scene",
        "demo",
        "--width",
        "120",
        "--height",
        "90",
        "--frames",
        "14",
        "--validation",
        "--at",
        "1:resize 1 1",
        "--at",
        "3:resize 120 90",
        "--at",
        at_small.as_str(),
        "--at",
        "6:minimize",
        "--at",
        "8:restore",
        "--at",
        "9:pause",
        "--at",
        "10:step",
        "--at",
        "11:set solver dfsph",
        "--at",
        "12:reset",
        "--screenshot",
        shot.to_str().unwrap(),
    ]);
    let t = text(&o);
    // Success also means no GPU object was left behind (view checks on closing).
    assert!(o.status.success(), "{t}");
    assert!(!t.contains("[vulkan ERROR"), "{t}");
    assert_eq!(rgba(&small).dimensions(), (64, 48));
    assert_eq!(rgba(&shot).dimensions(), (120, 90));
}

#[test]
fn view_refuses_bad_commands_and_scenes_clearly() {
    let o = fluidform(&["view", "--at", "x:pause"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("frame number"), "{}", text(&o));
    let o = view(&["--scene", "fountain", "--frames", "2"]);
    let t = text(&o);
    assert!(!o.status.success());
    assert!(t.contains("fluidform run --scene fountain"), "{t}");
}
