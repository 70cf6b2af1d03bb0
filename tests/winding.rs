//! The fast generalized winding number (control/winding.rs, Barill et al. 2018) against
//! the brute-force sum (control/inside.rs) on the meshes people find: a sphere with a
//! hole, two overlapping spheres, a non-manifold fin, inverted normals, a soup.
use fluidform::control::inside::winding_number;
use fluidform::control::winding::FastWinding;
use glam::Vec3;

/// A UV sphere about `c` of radius `r`, outward (counter-clockwise seen from outside).
fn sphere(c: Vec3, r: f32, rings: u32, segs: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut pos = Vec::new();
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segs {
            let ph = std::f32::consts::TAU * j as f32 / segs as f32;
            pos.push(c + r * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
        }
    }
    let at = |i: u32, j: u32| i * segs + j % segs;
    let mut idx = Vec::new();
    for i in 0..rings {
        for j in 0..segs {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i > 0 {
                idx.extend([a, d, b]);
            }
            if i + 1 < rings {
                idx.extend([d, c, b]);
            }
        }
    }
    (pos, idx)
}

fn join(a: (Vec<Vec3>, Vec<u32>), b: (Vec<Vec3>, Vec<u32>)) -> (Vec<Vec3>, Vec<u32>) {
    let n = a.0.len() as u32;
    let mut pos = a.0;
    pos.extend(b.0);
    let mut idx = a.1;
    idx.extend(b.1.iter().map(|i| i + n));
    (pos, idx)
}

/// Points on a jittered grid over the box, deterministic.
fn probes(lo: Vec3, hi: Vec3, n: u32) -> Vec<Vec3> {
    let mut v = Vec::new();
    let mut s = 12345u32;
    let mut rnd = || {
        s = s.wrapping_mul(1664525).wrapping_add(1013904223);
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..n {
        v.push(lo + (hi - lo) * Vec3::new(rnd(), rnd(), rnd()));
    }
    v
}

/// The fast sum within `tol` of the brute-force one at every probe, and the same inside
/// decision wherever the brute-force one is clear of 1/2 by more than `tol`. Returns the
/// brute-force values.
fn agrees(name: &str, mesh: &(Vec<Vec3>, Vec<u32>), lo: Vec3, hi: Vec3, tol: f64) -> Vec<f64> {
    let fast = FastWinding::new(&mesh.0, &mesh.1);
    let mut out = Vec::new();
    let mut worst = 0.0f64;
    for p in probes(lo, hi, 1500) {
        let (f, b) = (fast.winding(p), winding_number(&mesh.0, &mesh.1, p));
        worst = worst.max((f - b).abs());
        assert!(
            (f - b).abs() < tol,
            "{name}: at {p}: fast {f}, brute force {b}"
        );
        if (b - 0.5).abs() > tol {
            assert_eq!(fast.inside(p), b > 0.5, "{name}: inside at {p} (w = {b})");
        }
        out.push(b);
    }
    eprintln!("{name}: worst |fast - brute force| {worst:.2e} over 1500 probes");
    out
}

const TOL: f64 = 0.01;

#[test]
fn a_closed_sphere_is_one_inside_and_zero_outside() {
    let m = sphere(Vec3::ZERO, 1.0, 24, 48);
    let w = agrees("sphere", &m, Vec3::splat(-1.5), Vec3::splat(1.5), TOL);
    assert!(w.iter().any(|w| (w - 1.0).abs() < 1e-6) && w.iter().any(|w| w.abs() < 1e-6));
}

#[test]
fn a_sphere_with_a_hole_is_still_inside_away_from_the_hole() {
    let (pos, idx) = sphere(Vec3::ZERO, 1.0, 24, 48);
    // Drop the triangles of the top cap: an open mesh with one boundary loop.
    let idx: Vec<u32> = idx
        .chunks_exact(3)
        .filter(|t| t.iter().all(|&i| pos[i as usize].y < 0.9))
        .flatten()
        .copied()
        .collect();
    let m = (pos, idx);
    agrees(
        "sphere with a hole",
        &m,
        Vec3::splat(-1.5),
        Vec3::splat(1.5),
        TOL,
    );
    let fast = FastWinding::new(&m.0, &m.1);
    assert!(
        fast.inside(Vec3::new(0.0, -0.5, 0.0)),
        "the inside away from the hole"
    );
    assert!(!fast.inside(Vec3::new(0.0, 1.3, 0.0)), "above the hole");
}

#[test]
fn overlapping_spheres_sum_to_two_in_the_overlap() {
    let m = join(
        sphere(Vec3::ZERO, 1.0, 20, 40),
        sphere(Vec3::new(0.8, 0.0, 0.0), 1.0, 20, 40),
    );
    agrees(
        "two spheres",
        &m,
        Vec3::new(-1.5, -1.5, -1.5),
        Vec3::new(2.3, 1.5, 1.5),
        TOL,
    );
    let fast = FastWinding::new(&m.0, &m.1);
    assert!((fast.winding(Vec3::new(0.4, 0.0, 0.0)) - 2.0).abs() < TOL);
    assert!(fast.inside(Vec3::new(-0.5, 0.0, 0.0)) && fast.inside(Vec3::new(1.3, 0.0, 0.0)));
}

#[test]
fn a_non_manifold_fin_leaves_the_inside_alone() {
    let (mut pos, mut idx) = sphere(Vec3::ZERO, 1.0, 20, 40);
    // A fin on one of the sphere's edges: that edge now has three triangles.
    let (a, b) = (idx[0], idx[1]);
    pos.push(pos[a as usize] * 1.6);
    idx.extend([a, b, pos.len() as u32 - 1]);
    let m = (pos, idx);
    agrees(
        "non-manifold fin",
        &m,
        Vec3::splat(-1.7),
        Vec3::splat(1.7),
        TOL,
    );
}

#[test]
fn inverted_normals_wind_minus_one() {
    let (pos, idx) = sphere(Vec3::ZERO, 1.0, 20, 40);
    let idx: Vec<u32> = idx
        .chunks_exact(3)
        .flat_map(|t| [t[0], t[2], t[1]])
        .collect();
    let m = (pos, idx);
    let w = agrees("inverted", &m, Vec3::splat(-1.5), Vec3::splat(1.5), TOL);
    assert!(w.iter().any(|w| (w + 1.0).abs() < 1e-6));
    let fast = FastWinding::new(&m.0, &m.1);
    assert!((fast.winding(Vec3::ZERO) + 1.0).abs() < TOL);
}

#[test]
fn a_soup_of_unshared_shuffled_triangles_winds_as_its_surface() {
    let (pos, idx) = sphere(Vec3::ZERO, 1.0, 20, 40);
    // Every triangle its own three vertices, in a shuffled order.
    let mut tris: Vec<[Vec3; 3]> = idx
        .chunks_exact(3)
        .map(|t| [pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]])
        .collect();
    let n = tris.len();
    for i in 0..n {
        tris.swap(i, (i * 7919 + 13) % n);
    }
    let pos: Vec<Vec3> = tris.iter().flatten().copied().collect();
    let idx: Vec<u32> = (0..pos.len() as u32).collect();
    agrees(
        "soup",
        &(pos, idx),
        Vec3::splat(-1.5),
        Vec3::splat(1.5),
        TOL,
    );
}

#[test]
fn a_flat_sheet_is_nowhere_inside() {
    let pos = vec![
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(-1.0, 0.0, 1.0),
    ];
    let m = (pos, vec![0, 2, 1, 0, 3, 2]);
    let w = agrees("sheet", &m, Vec3::splat(-1.5), Vec3::splat(1.5), TOL);
    assert!(w.iter().all(|w| *w <= 0.5 + 1e-9), "a sheet bounds nothing");
}
