//! Runs repeat: the default scene played twice on the same device and binary gives the
//! same frames, byte for byte, and the same metrics in summary.json (its timings aside).
mod common;

/// `fluidform run` of the default scene for 20 frames at 160 x 160 into `dir`.
fn play(dir: &std::path::Path) {
    let out = dir.display().to_string();
    let o = common::fluidform(&[
        "run",
        "--frames",
        "20",
        "--width",
        "160",
        "--height",
        "160",
        "--save-every",
        "1",
        "--out",
        &out,
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", common::text(&o));
}

#[test]
fn the_default_scene_repeats_bit_for_bit() {
    let tmp = std::env::temp_dir().join(format!("fluidform-repeat-{}", std::process::id()));
    let (a, b) = (tmp.join("a"), tmp.join("b"));
    play(&a);
    play(&b);
    let mut pngs: Vec<_> = std::fs::read_dir(&a)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.file_name()))
        .filter(|n| n.to_string_lossy().ends_with(".png"))
        .collect();
    pngs.sort();
    assert!(pngs.len() >= 20, "{} frames written", pngs.len());
    let differ: Vec<_> = pngs
        .iter()
        .filter(|n| std::fs::read(a.join(n)).unwrap() != std::fs::read(b.join(n)).unwrap())
        .map(|n| n.to_string_lossy().to_string())
        .collect();
    assert!(
        differ.is_empty(),
        "frames that differ between two runs: {differ:?}"
    );
    // Everything but the GPU timings (pass_ms, frame_ms, fps) is the same.
    let (sa, sb) = (common::summary(&a), common::summary(&b));
    for key in ["frames", "stats", "memory_bytes"] {
        assert_eq!(
            sa[key], sb[key],
            "summary.json {key} differs between two runs"
        );
    }
    let _ = std::fs::remove_dir_all(&tmp);
}
