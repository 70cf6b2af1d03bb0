//! Thickness of the solid, not of the shell (issue 68): two nested shells, as clothes over a
//! body, with a hole in the outer one (an open mesh), report the outer solid's thickness;
//! a ray from the outer shell stops at the inner one a few millimetres in.
use super::common;
use fluidform::character::{self, thickness};
use glam::Mat3;
use serde_json::json;

const OUTER: f32 = 0.2;
const INNER: f32 = 0.194;

/// A latitude-longitude sphere of radius `r` about (0, r, 0), facing out: positions and
/// triangles (indices from `base`).
fn sphere(r: f32, base: u16) -> (Vec<[f32; 3]>, Vec<u16>) {
    let (rings, segs) = (16u16, 24u16);
    let mut p = vec![[0.0, 2.0 * r, 0.0]];
    for i in 1..rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segs {
            let ph = std::f32::consts::TAU * j as f32 / segs as f32;
            p.push([
                r * th.sin() * ph.cos(),
                r + r * th.cos(),
                r * th.sin() * ph.sin(),
            ]);
        }
    }
    p.push([0.0, 0.0, 0.0]);
    let at = |i: u16, j: u16| base + 1 + (i - 1) * segs + j % segs;
    let (top, bottom) = (base, base + p.len() as u16 - 1);
    let mut t = Vec::new();
    for j in 0..segs {
        t.extend([top, at(1, j + 1), at(1, j)]);
        t.extend([bottom, at(rings - 1, j), at(rings - 1, j + 1)]);
        for i in 1..rings - 1 {
            t.extend([at(i, j), at(i, j + 1), at(i + 1, j)]);
            t.extend([at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    (p, t)
}

#[test]
fn nested_shells_report_the_outer_solids_thickness() {
    let (mut pos, mut idx) = sphere(OUTER, 0);
    // A hole near the outer shell's bottom pole: the mesh is open, as layered meshes are.
    idx.drain(3..6);
    let (ip, ii) = sphere(INNER, pos.len() as u16);
    let lift = OUTER - INNER;
    pos.extend(ip.iter().map(|v| [v[0], v[1] + lift, v[2]]));
    idx.extend(ii);
    let mut d = common::gltf::Doc::default();
    let p = d.vec3(&pos);
    let i = d.indices(&idx);
    let doc = d.finish(json!({
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]
    }));
    let dir = tempfile::tempdir().unwrap();
    let ch = character::load(&common::gltf::write(dir.path(), "shells.gltf", &doc)).unwrap();
    assert!(!ch.check.closed());
    // A ray from the outer shell meets the inner one 6 mm in.
    let (rp, rn) = ch
        .skinned_at(&ch.rest_matrices(), character::Skinning::Lbs)
        .unwrap();
    let outer = pos.len() - ip.len();
    let rays = thickness::per_vertex(&rp, &rn, &ch.mesh.indices, None);
    let shell = rays[1..outer - 1]
        .iter()
        .flatten()
        .fold(f32::MAX, |a, b| a.min(*b));
    assert!(shell < 0.01, "the shells' gap {shell}");
    // The regions measure the solid: the outer sphere's diameter (the facets' chords
    // within 2%).
    let regions = thickness::regions(&ch, Mat3::IDENTITY).unwrap();
    assert!(!regions.is_empty());
    for r in &regions {
        assert!(
            (r.thickness - 2.0 * OUTER).abs() <= 0.02 * 2.0 * OUTER,
            "{r:?}: the solid is {} across",
            2.0 * OUTER
        );
    }
}
