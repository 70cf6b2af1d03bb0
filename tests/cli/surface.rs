//! `run --export-mesh`: the fluid's surface per exported frame, read back by an independent
//! OBJ reader (tobj) and a PLY header check: closed, facing out, and holding the particles'
//! volume within 10%.
use super::common::{fluidform, summary, text};
use std::collections::HashMap;

/// Directed edges without exactly one opposite partner (0: closed, consistently oriented).
fn open_edges(idx: &[u32]) -> usize {
    let mut d: HashMap<(u32, u32), u32> = HashMap::new();
    for t in idx.chunks(3) {
        for k in 0..3 {
            *d.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    d.iter()
        .filter(|(&(a, b), &n)| n != 1 || d.get(&(b, a)) != Some(&1))
        .count()
}

fn volume(pos: &[f32], idx: &[u32]) -> f64 {
    let p = |i: u32| [0, 1, 2].map(|k| pos[3 * i as usize + k] as f64);
    idx.chunks(3)
        .map(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            (a[0] * (b[1] * c[2] - b[2] * c[1])
                + a[1] * (b[2] * c[0] - b[0] * c[2])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

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
        assert_eq!(open_edges(&m.indices), 0, "{f} is not closed");
        let v = volume(&m.positions, &m.indices);
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
}
