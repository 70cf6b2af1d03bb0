//! The fidelity metrics (src/sim/control/fidelity.rs) against independent counts on known
//! particle sets: a sphere of particles filling a sphere target, the same set shifted,
//! spray, density in the shape, speed excess and the surface distance.
use fluidform::character::procedural::polygonise;
use fluidform::control::fidelity::{measure, Fluid, Frame};
use fluidform::control::inside::InsideTest;
use fluidform::control::mesh_distance::{tri_distance, SurfaceDistance};
use glam::Vec3;

const S: f32 = 0.02;

fn fluid() -> Fluid {
    let rest_density = 1000.0;
    Fluid {
        h: 1.68 * S,
        mass: rest_density * S * S * S,
        rest_density,
        spacing: S,
        floor: 0.0,
    }
}

/// A closed sphere mesh of radius `r` about `c`.
fn sphere(c: Vec3, r: f32) -> (Vec<Vec3>, Vec<u32>) {
    let f = move |p: Vec3| (p - c).length() - r;
    polygonise(&f, c - Vec3::splat(r), c + Vec3::splat(r), S / 2.0)
}

/// Lattice particles at the spacing inside radius `r` about `c`.
fn ball(c: Vec3, r: f32) -> Vec<Vec3> {
    let k = (r / S).ceil() as i32;
    let mut out = Vec::new();
    for z in -k..=k {
        for y in -k..=k {
            for x in -k..=k {
                let p = Vec3::new(x as f32, y as f32, z as f32) * S;
                if p.length() <= r {
                    out.push(c + p);
                }
            }
        }
    }
    out
}

fn run(
    pos: &[Vec3],
    vel: &[Vec3],
    mesh: &(Vec<Vec3>, Vec<u32>),
) -> fluidform::control::fidelity::Fidelity {
    let rho = vec![1000.0; pos.len()];
    let controlled = vec![true; pos.len()];
    let frame = Frame {
        pos,
        vel,
        rho: &rho,
        controlled: &controlled,
    };
    let inside = InsideTest::new(&mesh.0, &mesh.1);
    measure(&frame, ((&mesh.0, &mesh.1), &inside), 0.5, &fluid())
}

#[test]
fn a_filled_sphere_scores_high_and_a_shifted_one_low() {
    let (c, r) = (Vec3::new(0.0, 0.5, 0.0), 0.2);
    let mesh = sphere(c, r);
    let pos = ball(c, r);
    let vel = vec![Vec3::ZERO; pos.len()];
    let m = run(&pos, &vel, &mesh);
    assert!(m.fill > 0.9, "fill of a filled sphere {}", m.fill);
    assert!(m.iou > 0.9, "iou of a filled sphere {}", m.iou);
    assert_eq!(m.spray, 0.0);
    let d = m.density_in_shape.expect("fluid inside");
    assert!((d - 1.0).abs() < 1e-9, "density in shape {d}");
    assert!(
        (m.speed_excess + 0.5).abs() < 1e-6,
        "no fluid motion: -skin speed, got {}",
        m.speed_excess
    );
    assert!(
        m.surface_p95 < 1.0,
        "surface particles within a spacing: {}",
        m.surface_p95
    );
    // Shifted by one radius: half the sphere leaves, and the water beside it counts.
    let shifted: Vec<Vec3> = pos.iter().map(|p| *p + Vec3::new(r, 0.0, 0.0)).collect();
    let m = run(&shifted, &vel, &mesh);
    assert!(m.iou < 0.5, "iou shifted by a radius {}", m.iou);
    assert!(m.fill < 0.75, "fill shifted by a radius {}", m.fill);
    assert!(m.surface_p95 > 3.0, "shifted surface {}", m.surface_p95);
}

#[test]
fn fill_and_iou_match_an_independent_voxel_count() {
    // Half the sphere filled (particles below its centre): fill about a half, and iou the
    // same (no water outside); against a count by brute-force density on the voxels.
    let (c, r) = (Vec3::new(0.0, 0.5, 0.0), 0.15);
    let mesh = sphere(c, r);
    let pos: Vec<Vec3> = ball(c, r).into_iter().filter(|p| p.y < c.y).collect();
    let vel = vec![Vec3::ZERO; pos.len()];
    let m = run(&pos, &vel, &mesh);
    let f = fluid();
    let (h2, poly6) = (
        f.h * f.h,
        315.0 / (64.0 * std::f32::consts::PI * f.h.powi(9)),
    );
    let lo = c - Vec3::splat(r + 2.0 * f.h);
    let n = ((2.0 * (r + 2.0 * f.h)) / S).ceil() as i32;
    let (mut inside, mut filled, mut outside_occupied) = (0, 0, 0);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let v = lo + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * S;
                let rho: f32 = pos
                    .iter()
                    .map(|p| (*p - v).length_squared())
                    .filter(|r2| *r2 < h2)
                    .map(|r2| f.mass * poly6 * (h2 - r2).powi(3))
                    .sum();
                // The analytic sphere stands in for the mesh (its voxels differ by at most
                // the polygonisation's error at the boundary).
                let is_in = (v - c).length() < r;
                let occ = rho >= 0.5 * f.rest_density;
                inside += is_in as i32;
                filled += (is_in && occ) as i32;
                outside_occupied += (!is_in && occ) as i32;
            }
        }
    }
    let fill = filled as f64 / inside as f64;
    let iou = filled as f64 / (inside + outside_occupied) as f64;
    assert!(
        (m.fill - fill).abs() < 0.03,
        "fill {} against {fill}",
        m.fill
    );
    assert!((m.iou - iou).abs() < 0.03, "iou {} against {iou}", m.iou);
    assert!(
        m.fill > 0.35 && m.fill < 0.65,
        "half a sphere: fill {}",
        m.fill
    );
}

#[test]
fn spray_counts_isolated_airborne_particles_away_from_the_shape() {
    let (c, r) = (Vec3::new(0.0, 0.5, 0.0), 0.15);
    let mesh = sphere(c, r);
    let mut pos = ball(c, r);
    let n0 = pos.len();
    // Ten lone drops high above, and one resting on the floor far away (not spray).
    for k in 0..10 {
        pos.push(Vec3::new(0.3 + 0.1 * k as f32, 1.2, 0.0));
    }
    pos.push(Vec3::new(0.8, 0.001, 0.0));
    let mut vel = vec![Vec3::ZERO; pos.len()];
    vel[0] = Vec3::new(0.0, 3.0, 0.0);
    let m = run(&pos, &vel, &mesh);
    let expect = 10.0 / pos.len() as f64;
    assert!(
        (m.spray - expect).abs() < 1e-12,
        "spray {} against {expect} ({n0} in the ball)",
        m.spray
    );
    assert!(
        (m.speed_excess - 2.5).abs() < 1e-6,
        "speed excess {}",
        m.speed_excess
    );
}

#[test]
fn surface_distance_matches_brute_force() {
    let mesh = sphere(Vec3::new(0.1, 0.2, -0.1), 0.13);
    let d = SurfaceDistance::new(&mesh.0, &mesh.1, 0.03);
    let mut seed = 7u32;
    let mut rnd = || {
        seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..200 {
        let p = Vec3::new(rnd() - 0.4, rnd() - 0.3, rnd() - 0.6) * 1.5;
        let brute = mesh
            .1
            .chunks_exact(3)
            .map(|t| {
                tri_distance(
                    p,
                    mesh.0[t[0] as usize],
                    mesh.0[t[1] as usize],
                    mesh.0[t[2] as usize],
                )
            })
            .fold(f32::INFINITY, f32::min);
        let got = d.distance(p);
        assert!((got - brute).abs() < 1e-6, "at {p}: {got} against {brute}");
    }
}
