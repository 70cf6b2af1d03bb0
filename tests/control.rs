//! Control particles: inside tests against the generalized winding number, placement
//! uniformity against the lattice, binding weights (eq. 8, eq. 9, skin), bad input.
mod common;
use common::asset;
use fluidform::character::{self, Character};
use fluidform::control::binding::{self, pair_weights};
use fluidform::control::inside::{winding_number, InsideTest};
use fluidform::control::placement;
use fluidform::control::{BoneWeights, Placement};
use glam::Vec3;
use rand::{Rng, SeedableRng};

fn load(name: &str) -> Character {
    character::load(&asset(name)).unwrap()
}

#[test]
fn inside_test_agrees_with_the_winding_number() {
    for name in ["giraffe.obj", "spot.obj"] {
        let ch = load(name);
        let (pos, idx) = (&ch.mesh.positions, &ch.mesh.indices);
        let test = InsideTest::new(pos, idx);
        let (lo, hi) = character::check::bounds(pos);
        let mut rng = rand_pcg::Pcg32::seed_from_u64(3);
        let (mut checked, mut inside, mut wrong) = (0, 0, Vec::new());
        for _ in 0..3000 {
            let p = lo + (hi - lo) * Vec3::new(rng.random(), rng.random(), rng.random());
            let w = winding_number(pos, idx, p);
            if (w - 0.5).abs() < 0.4 {
                continue; // on the surface to within numerical noise
            }
            checked += 1;
            inside += (w > 0.5) as usize;
            if test.inside(p) != (w > 0.5) {
                wrong.push((p, w));
            }
        }
        assert!(
            checked > 2900 && inside > 100,
            "{name}: {checked} checked, {inside} inside"
        );
        assert!(
            wrong.is_empty(),
            "{name}: {} disagree: {:?}",
            wrong.len(),
            &wrong[..wrong.len().min(5)]
        );
    }
}

/// Nearest-neighbour distances of a point set (brute force over a grid of buckets).
fn nearest_distances(pts: &[Vec3]) -> Vec<f32> {
    pts.iter()
        .enumerate()
        .map(|(i, p)| {
            pts.iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, q)| p.distance(*q))
                .fold(f32::INFINITY, f32::min)
        })
        .collect()
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len() as f32
}

#[test]
fn random_placement_is_as_uniform_as_the_lattice() {
    let ch = load("giraffe.obj");
    let mesh = (ch.mesh.positions.as_slice(), ch.mesh.indices.as_slice());
    let spacing = 0.06;
    let lattice = placement::lattice(mesh, spacing);
    let random = placement::random(mesh, spacing, 5);
    let (nl, nr) = (nearest_distances(&lattice), nearest_distances(&random));
    let (ml, mr) = (mean(&nl), mean(&nr));
    assert!((ml - spacing).abs() < 1e-4, "lattice mean {ml}");
    assert!(
        (mr / ml - 1.0).abs() <= 0.2,
        "random mean nearest distance {mr} vs lattice {ml}"
    );
    // Blue noise: no two points closer than 0.8 spacing; 95% within 1.5 spacing of their
    // nearest (the rest sit alone in thin parts, where the lattice has lone points too).
    let mut sorted = nr.clone();
    sorted.sort_by(f32::total_cmp);
    let (lo, p95) = (sorted[0], sorted[sorted.len() * 95 / 100]);
    assert!(
        lo >= 0.8 * spacing && p95 <= 1.5 * spacing,
        "nearest distances {lo}, p95 {p95}"
    );
    let spread = |v: &[f32]| {
        let m = mean(v);
        (v.iter().map(|d| (d - m) * (d - m)).sum::<f32>() / v.len() as f32).sqrt() / m
    };
    assert!(
        spread(&nr) <= 0.2,
        "relative spread of nearest distances {}",
        spread(&nr)
    );
    // About the lattice's count (the same volume at the same density).
    let ratio = random.len() as f32 / lattice.len() as f32;
    assert!(
        (0.8..1.25).contains(&ratio),
        "{} random vs {} lattice",
        random.len(),
        lattice.len()
    );
    // Every random point is inside.
    let test = InsideTest::new(mesh.0, mesh.1);
    assert!(random.iter().all(|p| test.inside(*p)));
}

#[test]
fn placement_needs_an_inside_and_room() {
    let open = load("SimpleSkin.gltf");
    let rest = open.rest_positions().unwrap();
    let v = placement::place(&open, &rest, Placement::Vertices, 0.1, 1).unwrap();
    assert_eq!(v.len(), open.check.welded_vertices);
    let e = placement::place(&open, &rest, Placement::Random, 0.1, 1)
        .unwrap_err()
        .to_string();
    // An open sheet has no inside (its winding number is nowhere above 1/2).
    assert!(
        e.contains("SimpleSkin.gltf") && e.contains("10 boundary") && e.contains("no inside"),
        "{e}"
    );
    let g = load("giraffe.obj");
    let rest = g.rest_positions().unwrap();
    let e = placement::place(&g, &rest, Placement::Random, 50.0, 1)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no control particles") && e.contains("giraffe.obj"),
        "{e}"
    );
    let e = placement::place(&g, &rest, Placement::Random, -1.0, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("must be positive"), "{e}");
}

#[test]
fn bone_weights_by_eq8_eq9_and_skin() {
    // eq. 8 with n = 2: w_1 = d_2 / (d_1 + d_2); eq. 9 (reconstructed): inverse squares.
    assert_eq!(pair_weights(BoneWeights::Eq8, 1.0, 3.0), [0.75, 0.25]);
    let w = pair_weights(BoneWeights::Eq9, 1.0, 3.0);
    assert!(
        (w[0] - 0.9).abs() < 1e-6 && (w[1] - 0.1).abs() < 1e-6,
        "{w:?}"
    );
    assert_eq!(pair_weights(BoneWeights::Eq9, 0.0, 2.0), [1.0, 0.0]);
    let ch = character::load("builtin:walker").unwrap();
    let g = ch.skeleton.globals(&ch.skeleton.rest_locals());
    let bones = binding::bones(&ch, &g);
    assert_eq!(bones.len(), ch.skeleton.joints.len());
    let find = |n: &str| {
        ch.skeleton
            .joints
            .iter()
            .position(|j| ch.skeleton.nodes[j.node].name == n)
            .unwrap()
    };
    // Mid-thigh binds to the thigh first, the knee half to thigh and shin.
    let (thigh, shin) = (find("thigh_l"), find("shin_l"));
    let hip = g[ch.skeleton.joints[thigh].node].w_axis.truncate();
    let knee = g[ch.skeleton.joints[shin].node].w_axis.truncate();
    let rest = ch.rest_positions().unwrap();
    for how in [BoneWeights::Eq8, BoneWeights::Eq9] {
        let (j, w) = binding::bind(&ch, &bones, &[hip.lerp(knee, 0.5), knee], how, &rest);
        assert_eq!(j[0][0] as usize, thigh, "{how:?}");
        assert!(w[0][0] > 0.5 && (w[0][0] + w[0][1] - 1.0).abs() < 1e-6);
        assert!(
            w[1][0] >= 0.5
                && [j[1][0], j[1][1]].contains(&(shin as u16))
                && [j[1][0], j[1][1]].contains(&(thigh as u16))
        );
    }
    // skin: the weights of the nearest vertex.
    let p = rest[100] + Vec3::splat(1e-4);
    let (j, w) = binding::bind(&ch, &bones, &[p], BoneWeights::Skin, &rest);
    assert_eq!((j[0], w[0]), (ch.mesh.joints[100], ch.mesh.weights[100]));
}

#[test]
fn the_timeline_attaches_switches_unites_releases_and_scales() {
    use fluidform::control::timeline::{Action, Event, Timeline};
    let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
    let ev = |t: f32, a: Action, who: Option<&str>, k: f32| Event {
        strength: k,
        ..Event::new(t, a, who)
    };
    assert_eq!(Event::new(0.0, Action::Release, None).fade(), 0.2);
    // Given out of order: fired by time (file order at equal times).
    let events = [
        ev(0.5, Action::Union, Some("b"), 2.0),
        ev(0.0, Action::Attach, Some("a"), 1.0),
        ev(0.2, Action::Strength, None, 0.5),
        ev(1.0, Action::Switch, Some("c"), 1.0),
        ev(2.0, Action::Release, None, 1.0),
    ];
    let mut t = Timeline::new("s", &events, &names).unwrap();
    let state = |t: &Timeline| -> Vec<(bool, f32)> {
        (0..3).map(|i| (t.attached(i), t.strength(i))).collect()
    };
    assert!(t.due(-0.1).is_empty());
    assert_eq!(t.due(0.0).len(), 1);
    assert_eq!(state(&t), [(true, 1.0), (false, 1.0), (false, 1.0)]);
    // Two events due by 0.6: strength of the attached ones, then the union.
    let fired: Vec<Action> = t.due(0.6).iter().map(|(e, _)| e.action).collect();
    assert_eq!(fired, [Action::Strength, Action::Union]);
    assert_eq!(state(&t), [(true, 0.5), (true, 2.0), (false, 1.0)]);
    let (_, changes) = &t.due(1.0)[0];
    assert_eq!(changes.len(), 3, "switch releases a and b, attaches c");
    assert_eq!(state(&t), [(false, 0.5), (false, 2.0), (true, 1.0)]);
    t.due(5.0);
    assert!(state(&t).iter().all(|s| !s.0));
    // Every target attached from the start without a timeline.
    let all = Timeline::all_attached(&names);
    assert!((0..3).all(|i| all.attached(i)));
    // A strength below zero and a release of a target that is not attached are refused.
    let bad = [ev(0.0, Action::Attach, Some("a"), -1.0)];
    assert!(Timeline::new("s", &bad, &names)
        .unwrap_err()
        .to_string()
        .contains("strength must be at least 0"));
    let bad = [
        ev(0.0, Action::Attach, Some("a"), 1.0),
        ev(0.1, Action::Release, Some("b"), 1.0),
    ];
    let e = Timeline::new("s", &bad, &names).unwrap_err().to_string();
    assert!(e.contains("event 2") && e.contains("not attached"), "{e}");
}

/// The shape's fill at control particles (`--control-deficit shape`): a 20^3 lattice cube
/// at spacing 1, h = 2 (the fluid's 2 spacings), each particle a unit of its volume.
/// Interior particles see the whole kernel (1, the lattice sum being 1.0098 before the
/// cap), a face's centre about 0.82 (the lattice layer sits half a spacing inside the
/// face), a corner about 0.52; nothing exceeds 1.
#[test]
fn the_shape_fill_is_one_inside_and_falls_at_faces_and_corners() {
    use fluidform::control::placement::fill;
    let n = 20;
    let mut pts = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                pts.push(glam::Vec3::new(i as f32, j as f32, k as f32));
            }
        }
    }
    let f = fill(&pts, (n * n * n) as f32, 2.0);
    let at = |i: usize, j: usize, k: usize| f[(k * n + j) * n + i];
    assert!(f.iter().all(|v| *v > 0.0 && *v <= 1.0));
    assert!(
        (at(10, 10, 10) - 1.0).abs() < 1e-6,
        "interior {}",
        at(10, 10, 10)
    );
    let face = at(10, 10, 0);
    assert!((0.78..0.86).contains(&face), "face {face}");
    let corner = at(0, 0, 0);
    assert!((0.48..0.56).contains(&corner), "corner {corner}");
    // The same cube's particles standing for twice the volume read twice as full (capped).
    let g = fill(&pts, 2.0 * (n * n * n) as f32, 2.0);
    assert!((g[0] - (2.0 * corner).min(1.0)).abs() < 1e-5);
}

/// Which deficit a target measures: rest density unless the shape's fill is asked for,
/// which placements that put no particles inside refuse.
#[test]
fn the_deficit_measure_follows_the_preset_and_placement() {
    use fluidform::control::target::ControlDesc;
    use fluidform::control::{ControlPreset, Deficit, Placement};
    let d = ControlDesc::default();
    assert_eq!(d.deficit().unwrap(), Deficit::Rest);
    let shape = ControlDesc {
        preset: Some(ControlPreset::Thesis),
        deficit: Some(Deficit::Shape),
        ..ControlDesc::default()
    };
    assert_eq!(shape.deficit().unwrap(), Deficit::Shape);
    for p in [Placement::Vertices, Placement::Rays] {
        let mut d = ControlDesc {
            placement: p,
            ..ControlDesc::default()
        };
        assert_eq!(d.deficit().unwrap(), Deficit::Rest);
        d.deficit = Some(Deficit::Shape);
        let e = d.deficit().unwrap_err().to_string();
        assert!(e.contains("--control-deficit"), "{e}");
    }
}
