//! Particle systems beside the SPH fluid: depth compositing and what SPH scenes refuse.

use super::*;

/// A fluid block at rest seen from the front, and a sheet of still particles (drawn as
/// `draw`) across the view at depth `z` (none: no system).
fn sheet_scene(draw: &str, z: Option<f32>) -> String {
    let mut s = String::from(
        r#"name = "sheet"
frames = 1
[domain]
min = [0.0, 0.0, 0.0]
max = [0.4, 0.4, 0.4]
[fluid]
eos = "tait"
sound_speed = 20.0
clamp_negative_pressure = true
dt = 0.0005
substeps = 2
[[blocks]]
min = [0.1, 0.0, 0.1]
max = [0.3, 0.2, 0.3]
[camera]
eye = [0.2, 0.15, 1.6]
target = [0.2, 0.1, 0.2]
fov = 45.0
[look]
material = "phong"
tank = false
"#,
    );
    if let Some(z) = z {
        let (sort, px) = match draw {
            "points" => ("", "point_px = 6.0"),
            _ => ("sort = \"counting\"", ""),
        };
        s += &format!(
            r#"
[[system]]
name = "sheet"
capacity = 8192
draw = "{draw}"
{sort}
{px}
gravity = [0.0, 0.0, 0.0]
[system.emitter]
shape = "box"
centre = [0.2, 0.1, {z}]
half = [0.6, 0.5, 0.0]
burst = 6000
[system.particle]
size = {{ mean = 0.06, variance = 0.0 }}
life = {{ mean = 100.0, variance = 0.0 }}
color = {{ mean = [1.0, 0.2, 0.1, 1.0], variance = [0.0, 0.0, 0.0, 0.0] }}
"#
        );
    }
    s
}

/// Mean channel difference of two frames over the 5 x 5 pixels around `(x, y)`.
fn diff(a: &image::RgbaImage, b: &image::RgbaImage, (x, y): (i32, i32)) -> f32 {
    let mut sum = 0.0;
    for dy in -2..=2 {
        for dx in -2..=2 {
            let (pa, pb) = (
                a.get_pixel((x + dx) as u32, (y + dy) as u32),
                b.get_pixel((x + dx) as u32, (y + dy) as u32),
            );
            sum += (0..3)
                .map(|k| (pa[k] as f32 - pb[k] as f32).abs())
                .sum::<f32>();
        }
    }
    sum / 75.0
}

#[test]
fn particles_composite_with_the_metaball_fluid_by_depth() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (96u32, 64u32);
    let render = |name: &str, toml: String| -> image::RgbaImage {
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, toml).unwrap();
        let out = dir.path().join(name);
        let (ws, hs) = (w.to_string(), h.to_string());
        let o = fluidform(&[
            "run",
            "--scene",
            file.to_str().unwrap(),
            "--validation",
            "--quiet",
            "--width",
            &ws,
            "--height",
            &hs,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{name}: {}", text(&o));
        if name != "fluid" {
            let sum = common::summary(&out);
            let sys = &sum["stats"]["particle_systems"][0];
            assert_eq!(sys["births"].as_u64(), Some(6000), "{name}: {sys}");
            assert_eq!(sys["alive"].as_u64(), Some(6000), "{name}: {sys}");
        }
        image::open(out.join("frame_0000.png")).unwrap().to_rgba8()
    };
    // Pixels of a world point, as the march maps them (row 0 at NDC y = -1).
    let cam = Camera::look_at(
        Vec3::new(0.2, 0.15, 1.6),
        Vec3::new(0.2, 0.1, 0.2),
        45.0,
        w as f32 / h as f32,
    );
    let pixel = |p: Vec3| {
        let c = cam.view_proj() * p.extend(1.0);
        let ndc = c.truncate() / c.w;
        let x = ((ndc.x + 1.0) * 0.5 * w as f32 - 0.5).round() as i32;
        let y = ((ndc.y + 1.0) * 0.5 * h as f32 - 0.5).round() as i32;
        assert!(
            x >= 2 && y >= 2 && x < w as i32 - 2 && y < h as i32 - 2,
            "{p} -> {x},{y}"
        );
        (x, y)
    };
    let fluid = render("fluid", sheet_scene("sprites", None));
    // The block's front face, and the sheet beside the block.
    let (behind, front) = (-0.3, 0.9);
    let water = pixel(Vec3::new(0.2, 0.08, 0.3));
    let beside = pixel(Vec3::new(-0.25, 0.45, behind));
    for draw in ["sprites", "points"] {
        let back = render(&format!("{draw}-behind"), sheet_scene(draw, Some(behind)));
        let over = render(&format!("{draw}-front"), sheet_scene(draw, Some(front)));
        // Behind the water: hidden by it, seen beside it; in front: over it.
        let (hidden, seen, covers) = (
            diff(&back, &fluid, water),
            diff(&back, &fluid, beside),
            diff(&over, &fluid, water),
        );
        eprintln!(
            "{draw}: behind the water {hidden:.2}, beside it {seen:.2}, in front {covers:.2}"
        );
        assert!(
            hidden < 2.0,
            "{draw}: the sheet behind shows through the water ({hidden})"
        );
        assert!(
            seen > 30.0,
            "{draw}: the sheet behind is missing beside the water ({seen})"
        );
        assert!(
            covers > 30.0,
            "{draw}: the sheet in front does not cover the water ({covers})"
        );
    }
}

#[test]
fn sph_scenes_play_particle_systems_and_refuse_what_they_cannot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spray");
    let spray = format!("{}/tests/scenes/spray.toml", env!("CARGO_MANIFEST_DIR"));
    let o = fluidform(&[
        "run",
        "--scene",
        &spray,
        "--frames",
        "3",
        "--width",
        "64",
        "--height",
        "48",
        "--validation",
        "--quiet",
        "--integrator",
        "verlet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let sum = common::summary(&out);
    let systems = sum["stats"]["particle_systems"].as_array().unwrap();
    assert_eq!(systems.len(), 2);
    assert!(systems[0]["births"].as_u64().unwrap() > 0, "{systems:?}");
    assert_eq!(systems[1]["alive"].as_u64(), Some(300), "{systems:?}");
    assert!(systems.iter().all(|s| s["integrator"] == "verlet"));
    assert!(sum["stats"]["particles"].as_u64().unwrap() > 1000);
    // A system on the character, and systems with no fluid, are refused by name.
    let body = sheet_scene("sprites", Some(0.0)) + "[[system.collider]]\nkind = \"character\"\n";
    let alone = "name = \"alone\"\n[domain]\nmin = [-1.0, 0.0, -1.0]\nmax = [1.0, 2.0, 1.0]\n\
                 [character]\nfile = \"builtin:walker\"\n"
        .to_string()
        + &sheet_scene("sprites", Some(0.0))[sheet_scene("sprites", None).len()..];
    for (name, toml, expect) in [
        ("body", body, "do not reach yet"),
        ("alone", alone, "without fluid"),
    ] {
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, toml).unwrap();
        let o = fluidform(&["run", "--scene", file.to_str().unwrap(), "--quiet"]);
        assert!(!o.status.success(), "{name} ran");
        assert!(text(&o).contains(expect), "{name}: {}", text(&o));
        assert_eq!(text(&o).trim().lines().count(), 1, "{}", text(&o));
    }
}
