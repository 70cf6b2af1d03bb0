//! Any character a user brings (issue 48): a Z-up OBJ stood up by `up = "z"` or by
//! `rotation`, with one pivot for placement and fit; thin legs measured on the surface
//! and given 3 spacings; a rotated glTF fitted; water as a character scene's default
//! look; `inspect --up --picture`; `--samples`.
mod common;
use common::{asset, fluidform, text};
use fluidform::character::thickness;
use fluidform::scene::fit::{fit, WANT};
use fluidform::scene::Scene;
use glam::Vec3;
use std::path::Path;

/// A closed quadruped of voxels (Y up, facing +Z): legs 2 x 2 x 12, a 6 x 5 x 14 body,
/// a 3 x 3 x 8 neck, a 5 x 3 x 6 head; 28 tall, its legs 7% of its height. Written as an
/// OBJ with Z up (file y = -world z, file z = world y), faces welded on the voxel corners.
fn quadruped(path: &Path) {
    let boxes: [([i32; 3], [i32; 3]); 7] = [
        ([0, 0, 0], [2, 12, 2]),
        ([4, 0, 0], [6, 12, 2]),
        ([0, 0, 12], [2, 12, 14]),
        ([4, 0, 12], [6, 12, 14]),
        ([0, 12, 0], [6, 17, 14]),
        ([2, 17, 11], [5, 25, 14]),
        ([1, 25, 10], [6, 28, 16]),
    ];
    let full = |p: [i32; 3]| {
        boxes
            .iter()
            .any(|(a, b)| (0..3).all(|k| p[k] >= a[k] && p[k] < b[k]))
    };
    let mut verts: Vec<[i32; 3]> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut at = |v: [i32; 3]| -> usize {
        *index.entry(v).or_insert_with(|| {
            verts.push(v);
            verts.len()
        })
    };
    let mut faces = Vec::new();
    for x in -1..8 {
        for y in -1..30 {
            for z in -1..18 {
                let p = [x, y, z];
                if !full(p) {
                    continue;
                }
                for k in 0..3 {
                    for s in [-1, 1] {
                        let mut q = p;
                        q[k] += s;
                        if full(q) {
                            continue;
                        }
                        // The face on side s of axis k, wound outward.
                        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
                        let mut c = p;
                        c[k] += (s + 1) / 2;
                        let corner = |du: i32, dv: i32| {
                            let mut w = c;
                            w[u] += du;
                            w[v] += dv;
                            w
                        };
                        let mut quad = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        if s < 0 {
                            quad.reverse();
                        }
                        faces.push(quad.map(&mut at));
                    }
                }
            }
        }
    }
    let mut obj = String::new();
    for v in &verts {
        // World (x, y, z) at 0.05 m a voxel, written Z-up: file (x, -z, y).
        let w = [v[0], v[1], v[2]].map(|c| c as f32 * 0.05);
        obj.push_str(&format!("v {} {} {}\n", w[0], -w[2], w[1]));
    }
    for f in faces {
        obj.push_str(&format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]));
    }
    std::fs::write(path, obj).unwrap();
}

/// A temporary folder holding the quadruped as quad.obj, and that file.
fn with_quadruped() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("quad.obj");
    quadruped(&obj);
    (dir, obj)
}

/// The five-line scene a user writes, with `extra` lines under `[character]`.
fn five_lines(dir: &Path, file: &str, extra: &str) -> std::path::PathBuf {
    let path = dir.join(format!("scene-{}.toml", extra.len()));
    let body = format!(
        "name = \"quad\"\nframes = 2\n[character]\nfile = \"{file}\"\nheight = 1.4\n{extra}\n[pool]\n[control]\n"
    );
    std::fs::write(&path, body).unwrap();
    path
}

fn load(path: &Path) -> Scene {
    Scene::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The first pose's placed bounds.
fn placed(s: &Scene) -> (Vec3, Vec3) {
    let (ch, anim) = s.character.as_ref().unwrap().load().unwrap();
    fluidform::scene::character::placed_rest_bounds(&ch, &anim).unwrap()
}

#[test]
fn a_z_up_quadruped_stands_by_up_or_by_rotation_with_its_legs_at_three_spacings() {
    let (dir, obj) = with_quadruped();
    let file = obj.display().to_string();
    let mut fitted = Vec::new();
    for extra in ["up = \"z\"", "rotation = [-90.0, 0.0, 0.0]"] {
        let mut s = load(&five_lines(dir.path(), &file, extra));
        // It stands: feet on the floor, 1.4 m tall, in the fitted domain.
        let (lo, hi) = placed(&s);
        assert!(lo.y.abs() < 1e-4, "{extra}: its feet at y = {}", lo.y);
        assert!((hi.y - lo.y - 1.4).abs() < 1e-3, "{extra}: {lo}..{hi}");
        // 6 wide, 14 long: standing, not lying on its side or its nose.
        assert!(hi.z - lo.z > 2.0 * (hi.x - lo.x), "{extra}: {lo}..{hi}");
        let f = fit(&mut s).unwrap_or_else(|e| panic!("{extra}: {e}"));
        let (sp, why) = f.spacing.clone().unwrap();
        let d = &s.domain;
        assert!(d.min[1] == 0.0 && (0..3).all(|k| d.min[k] <= lo[k] && d.max[k] >= hi[k]));
        // Its legs, measured on the surface: four regions at the bottom, each 0.1 m
        // across in the file (2 voxels), 3 spacings or more at the fitted spacing.
        let (ch, anim) = s.character.as_ref().unwrap().load().unwrap();
        let scale = anim.placement.x_axis.truncate().length();
        let parts = thickness::regions(&ch, s.character.as_ref().unwrap().orientation()).unwrap();
        let legs: Vec<_> = parts
            .iter()
            .filter(|r| r.name.starts_with("bottom"))
            .collect();
        assert!(legs.len() >= 4, "{extra}: {parts:?}");
        for l in &legs {
            assert!((l.thickness - 0.1).abs() < 0.01, "{extra}: {l:?}");
            let across = l.thickness * scale / sp;
            assert!(
                across >= WANT - 1e-3,
                "{extra}: {} at {across:.2} spacings ({why})",
                l.name
            );
        }
        assert!(why.contains("thinnest"), "{extra}: {why}");
        assert!(f.thin.is_none(), "{extra}: {:?}", f.thin);
        fitted.push((sp, s.blocks.clone(), s.domain.clone()));
    }
    // One pivot: up and rotation place it alike (to rounding: one turns by a matrix, the
    // other by Euler angles).
    let near = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
    let ((s0, b0, d0), (s1, b1, d1)) = (&fitted[0], &fitted[1]);
    assert!((s0 - s1).abs() < 1e-6, "{s0} {s1}");
    assert!(b0.len() == 1 && b1.len() == 1);
    assert!(near(&b0[0].min, &b1[0].min) && near(&b0[0].max, &b1[0].max));
    assert!(near(&d0.min, &d1.min) && near(&d0.max, &d1.max));
    // Without its up axis it lies with its legs along Z: its 28 voxels of height there,
    // its 16 of length scaled to the 1.4 m asked.
    let s = load(&five_lines(dir.path(), &file, ""));
    let (lo, hi) = placed(&s);
    assert!(hi.z - lo.z > 1.5 * (hi.y - lo.y), "{lo}..{hi}");
}

#[test]
fn the_z_up_quadruped_plays_from_five_lines() {
    let (dir, obj) = with_quadruped();
    let scene = five_lines(dir.path(), &obj.display().to_string(), "up = \"z\"");
    let out = dir.path().join("out");
    let o = fluidform(&[
        "run",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--validation",
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("across the thinnest part, 'bottom"), "{t}");
    let s = common::summary(&out);
    assert_eq!(s["frames"], 2);
    // Water by default: the scene names no [look].
    assert_eq!(s["config"]["switches"]["material"], "tinted", "{s}");
}

#[test]
fn a_z_up_giraffe_and_a_rotated_gltf_fit_and_name_their_thin_parts() {
    let dir = tempfile::tempdir().unwrap();
    // The giraffe asset turned Z-up, as many OBJ exporters write it.
    let src = std::fs::read_to_string(asset("giraffe.obj")).unwrap();
    let mut obj = String::new();
    for l in src.lines() {
        match l.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f32> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
                obj.push_str(&format!("v {} {} {}\n", c[0], -c[2], c[1]));
            }
            None if l.starts_with("vn ") => {}
            None => obj.push_str(&format!("{l}\n")),
        }
    }
    let path = dir.path().join("giraffe_z.obj");
    std::fs::write(&path, obj).unwrap();
    let mut s = load(&five_lines(
        dir.path(),
        &path.display().to_string(),
        "up = \"z\"",
    ));
    let (lo, hi) = placed(&s);
    // Standing: 1.4 m tall, its neck and head forward (+Z), longer than it is wide.
    assert!(lo.y.abs() < 1e-4 && (hi.y - 1.4).abs() < 1e-3, "{lo}..{hi}");
    assert!(hi.z - lo.z > 2.0 * (hi.x - lo.x), "{lo}..{hi}");
    let f = fit(&mut s).unwrap();
    // Its legs and tail are thinner than the default budget keeps at 3 spacings: the fit
    // says which, and the spacing that would fit.
    let thin = f.thin.clone().unwrap();
    assert!(
        thin.contains("under 3 spacings") && thin.contains("3 at "),
        "{thin}"
    );
    assert_eq!(thin.lines().count(), 1);
    // A rotated glTF: CesiumMan turned 45 degrees and tilted 10 stands on the floor and
    // fits its domain, pool and control particles (the pivot is its turned bottom).
    let man = asset("CesiumMan.glb");
    let mut s = load(&five_lines(
        dir.path(),
        &man,
        "rotation = [10.0, 45.0, 0.0]",
    ));
    let (lo, hi) = placed(&s);
    assert!(lo.y.abs() < 1e-4 && (hi.y - 1.4).abs() < 1e-3, "{lo}..{hi}");
    fit(&mut s).unwrap();
    assert_eq!(s.blocks.len(), 1);
    let d = &s.domain;
    assert!((0..3).all(|k| d.min[k] <= lo[k] + 1e-4 && d.max[k] >= hi[k]));
}

#[test]
fn a_character_outside_its_domain_names_the_key_to_change() {
    let (dir, obj) = with_quadruped();
    let body = format!(
        "name = \"low\"\n[domain]\nmin = [-1.0, 0.0, -1.0]\nmax = [1.0, 2.0, 1.0]\n[character]\nfile = \"{}\"\nheight = 1.4\nup = \"z\"\nposition = [0.0, -0.6, 0.0]\n[pool]\n[control]\n",
        obj.display()
    );
    let path = dir.path().join("low.toml");
    std::fs::write(&path, body).unwrap();
    let e = fit(&mut load(&path)).unwrap_err().to_string();
    assert!(
        e.contains("below the domain's floor") && e.contains("[character] position"),
        "{e}"
    );
    assert!(e.contains("[character] up"), "{e}");
    // A bad up axis is refused by name.
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        format!(
            "name = \"b\"\n[character]\nfile = \"{}\"\nup = \"w\"\n",
            obj.display()
        ),
    )
    .unwrap();
    let e = Scene::load(bad.to_str().unwrap()).unwrap_err().to_string();
    assert!(e.contains("character.up") && e.contains("`w`"), "{e}");
}

#[test]
fn character_scenes_look_like_water_unless_they_say_otherwise() {
    let (dir, obj) = with_quadruped();
    use fluidform::render::Material;
    let s = load(&five_lines(
        dir.path(),
        &obj.display().to_string(),
        "up = \"z\"",
    ));
    assert_eq!(s.look.material, Some(Material::Tinted));
    assert_eq!(s.look.tank, Some(false));
    let p = dir.path().join("phong.toml");
    let body = std::fs::read_to_string(five_lines(dir.path(), &obj.display().to_string(), ""))
        .unwrap()
        + "[look]\nmaterial = \"phong\"\ntank = true\n";
    std::fs::write(&p, body).unwrap();
    let s = load(&p);
    assert_eq!(
        (s.look.material, s.look.tank),
        (Some(Material::Phong), Some(true))
    );
    // A scene without a character keeps the renderer's own defaults.
    let s = Scene::load("dam-break").unwrap();
    assert_eq!((s.look.material, s.look.tank), (None, None));
}

#[test]
fn inspect_names_the_up_axis_and_draws_the_rest_pose_standing() {
    let (dir, obj) = with_quadruped();
    let file = obj.display().to_string();
    let mut heights = Vec::new();
    for up in [None, Some("z")] {
        let png = dir.path().join(format!("{}.png", up.unwrap_or("y")));
        let mut args = vec!["inspect", &file, "--picture", png.to_str().unwrap()];
        if let Some(u) = up {
            args.extend(["--up", u]);
        }
        let o = fluidform(&args);
        let t = text(&o);
        assert!(o.status.success(), "{t}");
        let want = match up {
            None => "up axis            y (assumed: OBJ has no up convention",
            Some(_) => "up axis            z (as given)",
        };
        assert!(t.contains(want), "{t}");
        // The side view (right half): the drawn body's height against its length.
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (720, 360));
        let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
        for (x, y, p) in img.enumerate_pixels() {
            // The body's blue (the labels are black, the skeleton red, the floor brown).
            if x >= 360 && p[2] > 150 && p[0] < 150 {
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
        }
        heights.push((y1 - y0) as f32 / (x1 - x0) as f32);
    }
    // Lying (y assumed): seen from the side it is 28 long by 16 high (its legs point
    // sideways); standing (z given): 28 high by 16 long.
    assert!(heights[0] < 1.0 && heights[1] > 1.0, "{heights:?}");
    let o = fluidform(&["inspect", &file, "--up", "w"]);
    assert!(
        !o.status.success() && text(&o).contains("not one of"),
        "{}",
        text(&o)
    );
}

#[test]
fn samples_average_a_larger_picture_in_linear_light() {
    // One frame of the Z-up quadruped at 24 px with 4 samples a pixel is the 48 px frame
    // averaged over 2 x 2 blocks (the run is deterministic: tests/repeat.rs).
    let (dir, obj) = with_quadruped();
    let scene = five_lines(dir.path(), &obj.display().to_string(), "up = \"z\"");
    let shot = |size: &str, samples: &str| {
        let out = dir.path().join(format!("{size}-{samples}"));
        let o = fluidform(&[
            "run",
            "--scene",
            scene.to_str().unwrap(),
            "--frames",
            "1",
            "--width",
            size,
            "--height",
            size,
            "--samples",
            samples,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        image::open(out.join("frame_0000.png")).unwrap().to_rgba8()
    };
    let small = shot("24", "4");
    let large = shot("48", "1");
    assert_eq!(small.dimensions(), (24, 24));
    let lin = |v: u8| (v as f32 / 255.0).powf(2.2);
    let mut worst = 0i32;
    for (x, y, p) in small.enumerate_pixels() {
        for c in 0..3 {
            let mean = (0..4)
                .map(|k| lin(large.get_pixel(2 * x + k % 2, 2 * y + k / 2)[c]))
                .sum::<f32>()
                / 4.0;
            let want = (mean.powf(1.0 / 2.2) * 255.0).round() as i32;
            worst = worst.max((want - p[c] as i32).abs());
        }
    }
    assert!(worst <= 1, "a pixel off the 2 x 2 mean by {worst}");
    let o = fluidform(&["run", "--scene", scene.to_str().unwrap(), "--samples", "3"]);
    assert!(
        !o.status.success() && text(&o).contains("1, 4, 9 or 16"),
        "{}",
        text(&o)
    );
}
