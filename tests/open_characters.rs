//! Characters as people find them: an open, many-part robot (assets/RobotExpressive.glb,
//! CC0) accepted and filled by the winding number, against the brute-force sum; a closed
//! character keeps its ray-crossing answers exactly.
mod common;
use common::asset;
use fluidform::character::inside::{winding_number, Crossings, InsideTest};
use fluidform::character::{self, check, Character};
use fluidform::control::{placement, Placement};
use glam::Vec3;
use rand::{Rng, SeedableRng};

fn robot() -> Character {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/RobotExpressive.glb");
    character::load(p).unwrap()
}

/// `n` seeded points in the box of `pos`, grown by a tenth.
fn probes(pos: &[Vec3], n: usize) -> Vec<Vec3> {
    let (lo, hi) = check::bounds(pos);
    let pad = 0.1 * (hi - lo);
    let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
    (0..n)
        .map(|_| {
            let u = Vec3::new(rng.random(), rng.random(), rng.random());
            lo - pad + u * (hi - lo + 2.0 * pad)
        })
        .collect()
}

#[test]
fn an_open_many_part_robot_is_filled_by_the_winding_number() {
    let ch = robot();
    let c = &ch.check;
    assert_eq!(
        (c.boundary_edges, c.nonmanifold_edges, c.components),
        (232, 0, 63)
    );
    assert!(ch.parts.len() >= 14, "{} parts", ch.parts.len());
    let open = ch.open_parts();
    assert!(open.len() > 1 && open.len() < ch.parts.len(), "{open:?}");
    let line: Vec<&String> = ch
        .warnings
        .iter()
        .filter(|w| w.contains("is open"))
        .collect();
    assert_eq!(line.len(), 1, "{:?}", ch.warnings);
    assert!(line[0].contains("232 boundary") && line[0].contains("63 components"));
    // The inside test is the winding number, and agrees with the brute-force sum wherever
    // that is not within 0.01 of the threshold.
    let rest = ch.rest_positions().unwrap();
    let idx = &ch.mesh.indices;
    let test = InsideTest::new(&rest, idx);
    assert!(test.is_open());
    let pts = probes(&rest, 600);
    let fast = test.inside_all(&pts);
    let (mut inside, mut agree, mut counted) = (0, 0, 0);
    for (p, f) in pts.iter().zip(&fast) {
        let w = winding_number(&rest, idx, *p);
        if (w - 0.5).abs() < 0.01 {
            continue;
        }
        counted += 1;
        inside += (w > 0.5) as usize;
        agree += (*f == (w > 0.5)) as usize;
    }
    assert_eq!(agree, counted, "{agree} of {counted} probes agree");
    assert!(inside > 20, "only {inside} probes inside");
    // Placement fills it; every point is inside by the brute-force sum.
    ch.require_solid(&rest).unwrap();
    let spacing = (check::bounds(&rest).1.y - check::bounds(&rest).0.y) / 40.0;
    let pts = placement::place(&ch, &rest, Placement::Random, spacing, 3).unwrap();
    assert!(pts.len() > 500, "{} control particles", pts.len());
    for p in pts.iter().step_by(pts.len() / 100) {
        assert!(winding_number(&rest, idx, *p) > 0.5, "{p} is outside");
    }
    // Its volume by voxels is within a tenth of the lattice count's (the same test, two
    // resolutions), and not the signed volume, which counts the overlapping parts twice.
    let (v, voxels) = character::inside::volume(&rest, idx, spacing / 2.0, false);
    assert!(voxels.is_some());
    let lattice = placement::lattice((&rest, idx), spacing).len() as f64 * (spacing as f64).powi(3);
    assert!(
        (v / lattice - 1.0).abs() < 0.1,
        "voxels {v} vs lattice {lattice}"
    );
    // The GPU's ray placement still needs a closed mesh, and says so.
    let e = placement::place(&ch, &rest, Placement::Rays, spacing, 3).unwrap_err();
    assert!(e.to_string().contains("not closed"), "{e}");
}

#[test]
fn a_closed_character_keeps_its_crossing_answers() {
    let ch = character::load(&asset("CesiumMan.glb")).unwrap();
    let rest = ch.rest_positions().unwrap();
    let idx = &ch.mesh.indices;
    let test = InsideTest::new(&rest, idx);
    assert!(!test.is_open());
    assert!(ch.open_parts().is_empty());
    let crossings = Crossings::new(&rest, idx);
    let pts = probes(&rest, 4000);
    let all = test.inside_all(&pts);
    for (p, a) in pts.iter().zip(&all) {
        assert_eq!(*a, crossings.inside(*p), "{p}");
        assert_eq!(*a, test.inside(*p));
    }
    assert!(all.iter().filter(|a| **a).count() > 40);
    // Its volume is its signed volume, exactly.
    let (v, voxels) = character::inside::volume(&rest, idx, 0.01, true);
    assert!(voxels.is_none());
    assert_eq!(v, check::signed_volume(&rest, idx).abs());
}

#[test]
fn a_run_reports_open_and_thin_parts_and_its_clip() {
    let dir = tempfile::tempdir().unwrap();
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/RobotExpressive.glb");
    let scene = format!(
        "name = \"robot\"\n[character]\nfile = \"{file}\"\nheight = 1.7\n[pool]\n[control]\n"
    );
    let path = dir.path().join("robot.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out");
    let r = common::fluidform(&[
        "run",
        "--scene",
        path.to_str().unwrap(),
        "--frames",
        "2",
        "--render",
        "points",
        "--width",
        "64",
        "--height",
        "64",
        "--validation",
        "--out",
        out.to_str().unwrap(),
    ]);
    let log = common::text(&r);
    assert!(r.status.success(), "{log}");
    assert!(
        log.contains("plays clip 'Dance'; 11 of 19 parts open: 'Torso_2' (40 boundary"),
        "{log}"
    );
    assert!(
        log.contains("open mesh (232 boundary and 0 non-manifold edges, 63 components): volume"),
        "{log}"
    );
    let s = common::summary(&out);
    let c = &s["stats"]["character"];
    assert_eq!(c["animation"], "Dance");
    assert_eq!(c["open_parts"].as_array().unwrap().len(), 11, "{c}");
    let thin = c["thin_parts"].as_array().unwrap();
    assert!(!thin.is_empty(), "{c}");
    assert!(
        thin.iter().all(|t| t["spacings"].as_f64().unwrap() < 3.0),
        "{c}"
    );
}
