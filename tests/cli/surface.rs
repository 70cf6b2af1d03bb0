//! `run --export-mesh`: the fluid's surface per exported frame, read back by an independent
//! OBJ reader (tobj) and a PLY header check: closed, facing out, and holding the particles'
//! volume within 10%.
use super::common::{fluidform, summary, text};
use fluidform::isosurface::Mesh;

#[test]
fn exported_surfaces_are_closed_and_hold_the_fluids_volume() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mesh");
    let o = fluidform(&[
        "run",
        "--scene",
        "demo",
        "--frames",
        "2",
        "--save-every",
        "0",
        "--quiet",
        "--export-mesh",
        "obj",
        "--export-every",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let s = summary(&out);
    let fluid = &s["config"]["fluid"];
    let (mass, rest) = (
        fluid["mass"].as_f64().unwrap(),
        fluid["rest_density"].as_f64().unwrap(),
    );
    let n = s["stats"]["particles"].as_f64().unwrap();
    let want = n * mass / rest;
    for f in ["surface_0000.obj", "surface_0001.obj"] {
        let opts = tobj::LoadOptions {
            single_index: true,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj(out.join(f), &opts).unwrap();
        let m = &models[0].mesh;
        assert!(m.indices.len() > 300 && !m.normals.is_empty(), "{f}");
        // What tobj read, measured as a mesh.
        let read = Mesh {
            positions: m.positions.chunks(3).map(|p| [p[0], p[1], p[2]]).collect(),
            normals: Vec::new(),
            indices: m.indices.clone(),
        };
        assert_eq!(read.open_edges(), 0, "{f} is not closed");
        let v = read.volume();
        assert!(
            (v / want - 1.0).abs() < 0.10,
            "{f}: volume {v} against the particles' {want}"
        );
    }
    // PLY: the same surface, binary, with its header.
    let out2 = dir.path().join("ply");
    let o = fluidform(&[
        "run",
        "--scene",
        "demo",
        "--frames",
        "1",
        "--save-every",
        "0",
        "--quiet",
        "--export-mesh",
        "ply",
        "--out",
        out2.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let bytes = std::fs::read(out2.join("surface_0000.ply")).unwrap();
    let head = String::from_utf8_lossy(&bytes[..400.min(bytes.len())]);
    assert!(
        head.starts_with("ply\nformat binary_little_endian 1.0"),
        "{head}"
    );
    assert!(
        head.contains("property list uchar int vertex_indices"),
        "{head}"
    );
    // Read back as a PLY reader does, from the header's elements and properties: closed,
    // and the particles' volume.
    let read = read_ply(&bytes);
    assert_eq!(read.open_edges(), 0, "the PLY surface is not closed");
    let v = read.volume();
    assert!(
        (v / want - 1.0).abs() < 0.10,
        "PLY volume {v} against {want}"
    );
}

/// A binary little-endian PLY's vertices (x, y, z among float properties) and faces (a
/// `list uchar int` property), laid out as its header declares.
fn read_ply(bytes: &[u8]) -> Mesh {
    let end = b"end_header\n";
    let at = bytes
        .windows(end.len())
        .position(|w| w == end)
        .expect("end_header")
        + end.len();
    let header = std::str::from_utf8(&bytes[..at]).unwrap();
    let (mut vertices, mut faces, mut props) = (0usize, 0usize, Vec::new());
    let mut element = "";
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["element", name, n] => {
                element = if *name == "vertex" { "vertex" } else { "face" };
                *(if *name == "vertex" {
                    &mut vertices
                } else {
                    &mut faces
                }) = n.parse().unwrap();
            }
            ["property", "float", name] if element == "vertex" => props.push(name.to_string()),
            ["property", ty, ..] if element == "vertex" => panic!("vertex property of type {ty}"),
            _ => {}
        }
    }
    let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let xyz = ["x", "y", "z"].map(|a| props.iter().position(|p| p == a).expect(a));
    let stride = 4 * props.len();
    let positions = (0..vertices)
        .map(|i| xyz.map(|k| f32_at(at + i * stride + 4 * k)))
        .collect();
    let mut o = at + vertices * stride;
    let mut indices = Vec::new();
    for _ in 0..faces {
        assert_eq!(bytes[o], 3, "a face that is not a triangle");
        for k in 0..3 {
            let b = &bytes[o + 1 + 4 * k..o + 5 + 4 * k];
            indices.push(i32::from_le_bytes(b.try_into().unwrap()) as u32);
        }
        o += 13;
    }
    assert_eq!(o, bytes.len(), "bytes left after the faces");
    Mesh {
        positions,
        normals: Vec::new(),
        indices,
    }
}

#[test]
fn the_other_surfaces_draw_and_refuse_what_they_do_not_use() {
    let dir = tempfile::tempdir().unwrap();
    for (kind, passes) in [
        ("screen-space", ["splat", "smooth", "normals", "shade"]),
        ("mesh", ["density", "cells", "raster", "shade"]),
    ] {
        let out = dir.path().join(kind);
        let o = fluidform(&[
            "run",
            "--scene",
            "drop",
            "--frames",
            "2",
            "--quiet",
            "--width",
            "64",
            "--height",
            "48",
            "--surface",
            kind,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{kind}: {}", text(&o));
        assert_eq!(summary(&out)["stats"]["render"]["renderer"], kind);
        let timings = std::fs::read_to_string(out.join("timings.csv")).unwrap();
        for p in passes {
            assert!(
                timings.contains(&format!("render/{p}")),
                "{kind}: no {p} scope"
            );
        }
        assert!(out.join("frame_0001.png").exists());
    }
    // A scene's [look] picks the surface; the switch overrides it.
    let scene = dir.path().join("look.toml");
    std::fs::write(
        &scene,
        "name = \"look\"\nframes = 1\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [0.5, 0.5, 0.5]\n\
         [[blocks]]\nmin = [0.1, 0.0, 0.1]\nmax = [0.3, 0.2, 0.3]\n\
         [look]\nsurface = \"mesh\"\nsize = [64, 48]\n",
    )
    .unwrap();
    for (extra, want) in [(None, "mesh"), (Some("screen-space"), "screen-space")] {
        let out = dir.path().join(format!("look-{want}"));
        let mut a = vec!["run", "--scene", scene.to_str().unwrap(), "--quiet"];
        a.extend(extra.map(|k| ["--surface", k]).into_iter().flatten());
        a.extend(["--out", out.to_str().unwrap()]);
        let o = fluidform(&a);
        assert!(o.status.success(), "{}", text(&o));
        assert_eq!(summary(&out)["stats"]["render"]["renderer"], want);
    }
    for (args, why) in [
        (
            &["--surface", "mesh", "--list", "abuffer"][..],
            "--list belongs",
        ),
        (
            &["--surface", "mesh", "--mesh-cell", "0"][..],
            "--mesh-cell must be",
        ),
        (
            &["--mesh-cell", "1"][..],
            "--mesh-cell belongs to --surface mesh",
        ),
        (&["--render", "points", "--surface", "mesh"][..], "surface"),
    ] {
        let mut a = vec!["run", "--scene", "drop", "--frames", "1", "--quiet"];
        a.extend_from_slice(args);
        let o = fluidform(&a);
        assert!(!o.status.success(), "{args:?} was accepted");
        let t = text(&o);
        assert!(t.contains(why) && t.lines().count() <= 3, "{args:?}: {t}");
    }
}
