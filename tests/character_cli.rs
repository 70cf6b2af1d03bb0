//! Characters from the command line: inspect, a character alone, a character with fluid
//! (both views), --show-mesh and --skinning, and one-line errors for bad scenes.
mod common;
use common::{asset, fluidform, summary, text};
use std::path::{Path, PathBuf};

fn scene(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/scenes")
        .join(name)
        .display()
        .to_string()
}

/// Pixels of a PNG that `pred` accepts, as a fraction.
fn fraction(png: &Path, pred: impl Fn([u8; 4]) -> bool) -> f64 {
    let img = image::open(png).unwrap().to_rgba8();
    let hits = img.pixels().filter(|p| pred(p.0)).count();
    hits as f64 / (img.width() * img.height()) as f64
}

/// The shaded character's warm clay (not the wireframe's yellow, the sky or the water).
fn clay(p: [u8; 4]) -> bool {
    let [r, g, b] = [p[0] as i32, p[1] as i32, p[2] as i32];
    r > 90 && r > g + 20 && g > b + 15
}

#[test]
fn inspect_reports_text_and_json() {
    let o = fluidform(&["inspect", &asset("CesiumMan.glb")]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    for needle in [
        "triangles          4672",
        "3273 (2338 welded)",
        "19 (up to 4",
        "2.000 s, 57 channels",
        "closed             yes",
    ] {
        assert!(t.contains(needle), "'{needle}' missing from:\n{t}");
    }
    let o = fluidform(&["inspect", &asset("SimpleSkin.gltf"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["boundary_edges"], 10);
    assert_eq!(v["closed"], false);
    assert_eq!(v["normals"], "computed");
    assert_eq!(v["joints"], 2);
    let o = fluidform(&["inspect", "missing.glb"]);
    assert_eq!(o.status.code(), Some(1));
    let t = text(&o);
    assert!(t.contains("missing.glb") && t.lines().count() == 1, "{t}");
}

#[test]
fn a_character_alone_plays_and_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("walker");
    let o = fluidform(&[
        "run",
        "--scene",
        "walker",
        "--frames",
        "3",
        "--out",
        out.to_str().unwrap(),
        "--validation",
        "--width",
        "160",
        "--height",
        "160",
        "--quiet",
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let s = summary(&out);
    let c = &s["stats"]["character"];
    assert_eq!(c["joints"], 13, "{s}");
    assert_eq!(c["animation"], "walk");
    assert_eq!(c["skinning"], "lbs");
    assert!(
        s["pass_ms"]["skin"]["median"].as_f64().unwrap() > 0.0,
        "{s}"
    );
    assert_eq!(s["validation"]["errors"], 0);
    let shaded = fraction(&out.join("frame_0002.png"), clay);
    assert!(
        shaded > 0.03 && shaded < 0.5,
        "clay-coloured fraction {shaded}"
    );
    // The wireframe (dual quaternions): yellow edges, fewer pixels than the shaded body.
    let wire = dir.path().join("wire");
    let o = fluidform(&[
        "run",
        "--scene",
        "walker",
        "--frames",
        "3",
        "--out",
        wire.to_str().unwrap(),
        "--show-mesh",
        "wire",
        "--skinning",
        "dqs",
        "--width",
        "160",
        "--height",
        "160",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(summary(&wire)["stats"]["character"]["skinning"], "dqs");
    let yellow = fraction(&wire.join("frame_0002.png"), |p| {
        p[0] > 150 && p[1] > 150 && p[2] < 120
    });
    assert!(
        yellow > 0.01 && fraction(&wire.join("frame_0002.png"), clay) < 0.001,
        "wire {yellow}"
    );
    // Nothing to draw.
    let o = fluidform(&[
        "run",
        "--scene",
        "walker",
        "--frames",
        "1",
        "--show-mesh",
        "off",
        "--out",
        wire.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("nothing to draw"), "{}", text(&o));
}

#[test]
fn cesium_man_scene_file_is_placed_at_its_height() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cm");
    let o = fluidform(&[
        "run",
        "--scene",
        &scene("cesium_man.toml"),
        "--frames",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--width",
        "128",
        "--height",
        "128",
        "--quiet",
        "--validation",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let c = &summary(&out)["stats"]["character"];
    assert!((c["height"].as_f64().unwrap() - 1.5).abs() < 1e-3, "{c}");
    assert_eq!(c["joints"], 19);
    assert!(fraction(&out.join("frame_0001.png"), clay) > 0.01);
}

#[test]
fn a_character_beside_fluid_in_both_views() {
    let dir = tempfile::tempdir().unwrap();
    for render in ["metaballs", "points"] {
        let out = dir.path().join(render);
        let o = fluidform(&[
            "run",
            "--scene",
            &scene("walker_in_water.toml"),
            "--frames",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--width",
            "120",
            "--height",
            "96",
            "--quiet",
            "--validation",
            "--render",
            render,
        ]);
        assert!(o.status.success(), "{render}: {}", text(&o));
        let s = summary(&out);
        assert_eq!(s["stats"]["character"]["joints"], 13);
        let png = out.join("frame_0000.png");
        let body = fraction(&png, clay);
        let water = fraction(&png, |p| p[2] > 120 && p[2] as i32 > p[0] as i32 + 50);
        assert!(body > 0.01, "{render}: the character is drawn ({body})");
        assert!(water > 0.01, "{render}: the fluid is drawn ({water})");
    }
}

#[test]
fn bad_character_scenes_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(scene("cesium_man.toml")).unwrap();
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "missing.toml",
            "file = \"nowhere.glb\"",
            &["nowhere.glb", "No such file"],
        ),
        (
            "anim.toml",
            "animation = \"run\"",
            &["no animation 'run'", "0 'animation0'"],
        ),
        ("both.toml", "scale = 2.0", &["height or scale"]),
        ("mirror.toml", "speed = -1.0", &["speed"]),
    ];
    for (name, line, needles) in cases {
        let key = line.split(" = ").next().unwrap();
        let text_in: String = base
            .lines()
            .filter(|l| !l.starts_with(&format!("{key} =")))
            .map(|l| format!("{l}\n"))
            .collect::<String>()
            + line
            + "\n";
        let text_in = text_in.replace(
            "../../../shared",
            &Path::new(&asset("CesiumMan.glb"))
                .parent()
                .unwrap()
                .parent()
                .unwrap()
                .display()
                .to_string(),
        );
        let p = dir.path().join(name);
        std::fs::write(&p, text_in).unwrap();
        let o = fluidform(&[
            "run",
            "--scene",
            p.to_str().unwrap(),
            "--frames",
            "1",
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {t}");
        assert_eq!(t.trim().lines().count(), 1, "{name}: {t}");
        for n in needles {
            assert!(t.contains(n), "{name}: '{n}' missing from {t}");
        }
    }
    // Character switches on a scene without a character.
    let o = fluidform(&[
        "run",
        "--scene",
        "drop",
        "--frames",
        "1",
        "--skinning",
        "dqs",
        "--out",
        dir.path().join("o").to_str().unwrap(),
    ]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("--skinning does not apply"), "{t}");
}
