//! Control-particle placement in the rest pose (seed 000, 3.2): `vertices` (one per welded
//! vertex, no inside test), `random` (seeded Poisson-disk points in the mesh's box kept by
//! the inside test: uniform spacing, unlike plain random points), and the cubic lattice
//! the other two are compared against.
use super::inside::InsideTest;
use crate::character::{check, Character};
use crate::control::Placement;
use crate::error::{Error, Result};
use glam::Vec3;
use rand::{Rng, SeedableRng};

/// Rest-pose (placed) positions of the character's vertices.
pub type RestMesh<'a> = (&'a [Vec3], &'a [u32]);

/// One control particle per welded vertex.
pub fn vertices(positions: &[Vec3]) -> Vec<Vec3> {
    let (remap, n) = check::weld(positions);
    let mut out = vec![Vec3::ZERO; n];
    for (v, &w) in remap.iter().enumerate() {
        out[w as usize] = positions[v];
    }
    out
}

/// Lattice points at `spacing` inside the mesh (the reference for uniformity).
pub fn lattice(mesh: RestMesh, spacing: f32) -> Vec<Vec3> {
    lattice_in(&InsideTest::new(mesh.0, mesh.1), mesh.0, spacing)
}

/// Lattice points at `spacing` in the box of `positions` that `inside` keeps.
fn lattice_in(inside: &InsideTest, positions: &[Vec3], spacing: f32) -> Vec<Vec3> {
    let (lo, hi) = check::bounds(positions);
    let dims = ((hi - lo) / spacing).ceil().as_uvec3();
    let (centres, kept) = inside.voxels(lo, dims, spacing);
    keep(centres, &kept)
}

fn keep(points: Vec<Vec3>, kept: &[bool]) -> Vec<Vec3> {
    points
        .into_iter()
        .zip(kept)
        .filter(|(_, k)| **k)
        .map(|(p, _)| p)
        .collect()
}

/// Ratio of the Poisson-disk radius to the spacing: a maximal Poisson-disk set of radius r
/// holds about 0.6 / r^3 points per unit volume, so this gives the lattice's count (its
/// nearest neighbours then lie about 0.93 spacings apart).
const DISK: f32 = 0.84;

/// Bridson's Poisson-disk sampling (2007) in the mesh's box, kept inside: no two points
/// closer than `DISK * spacing`, the box filled (30 tries per active point).
pub fn random(mesh: RestMesh, spacing: f32, seed: u64) -> Vec<Vec3> {
    random_in(&InsideTest::new(mesh.0, mesh.1), mesh.0, spacing, seed)
}

/// Poisson-disk points in the box of `positions` that `inside` keeps.
fn random_in(inside: &InsideTest, positions: &[Vec3], spacing: f32, seed: u64) -> Vec<Vec3> {
    let (lo, hi) = check::bounds(positions);
    let r = DISK * spacing;
    let cell = r / 3f32.sqrt();
    let dims = ((hi - lo) / cell).ceil().as_uvec3().max(glam::UVec3::ONE);
    let (dx, dy, dz) = (dims.x as usize, dims.y as usize, dims.z as usize);
    let mut grid = vec![u32::MAX; dx * dy * dz];
    let cell_of = |p: Vec3| {
        let c = ((p - lo) / cell).floor().as_uvec3().min(dims - 1);
        (c.x as usize, c.y as usize, c.z as usize)
    };
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut pts: Vec<Vec3> = Vec::new();
    let mut active = Vec::new();
    let first = lo + (hi - lo) * Vec3::new(rng.random(), rng.random(), rng.random());
    let (x, y, z) = cell_of(first);
    grid[x + dx * (y + dy * z)] = 0;
    pts.push(first);
    active.push(0usize);
    while let Some(k) = (!active.is_empty()).then(|| rng.random_range(0..active.len())) {
        let base = pts[active[k]];
        let mut found = false;
        for _ in 0..30 {
            // Uniform in the shell [r, 2r].
            let dir = loop {
                let d = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0;
                if d.length_squared() <= 1.0 && d.length_squared() > 1e-6 {
                    break d.normalize();
                }
            };
            let p = base + dir * r * (1.0 + rng.random::<f32>());
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                continue;
            }
            let (x, y, z) = cell_of(p);
            let mut ok = true;
            'near: for zz in z.saturating_sub(2)..(z + 3).min(dz) {
                for yy in y.saturating_sub(2)..(y + 3).min(dy) {
                    for xx in x.saturating_sub(2)..(x + 3).min(dx) {
                        let q = grid[xx + dx * (yy + dy * zz)];
                        if q != u32::MAX && pts[q as usize].distance_squared(p) < r * r {
                            ok = false;
                            break 'near;
                        }
                    }
                }
            }
            if ok {
                grid[x + dx * (y + dy * z)] = pts.len() as u32;
                active.push(pts.len());
                pts.push(p);
                found = true;
                break;
            }
        }
        if !found {
            active.swap_remove(k);
        }
    }
    let kept = inside.inside_all(&pts);
    keep(pts, &kept)
}

/// Control particles of `ch` (rest positions `rest`, placed) by `how` at `spacing`.
pub fn place(
    ch: &Character,
    rest: &[Vec3],
    how: Placement,
    spacing: f32,
    seed: u64,
) -> Result<Vec<Vec3>> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(Error::Param(format!(
            "--control-spacing must be positive, got {spacing}"
        )));
    }
    // The character's own closedness picks the test (decided once, at its rest pose).
    let inside = || InsideTest::of(rest, &ch.mesh.indices, ch.check.closed());
    let pts = match how {
        Placement::Vertices => vertices(rest),
        Placement::Random => {
            ch.require_solid(rest)?;
            random_in(&inside(), rest, spacing, seed)
        }
        // Placed on the GPU every frame (control::rays); here the rest pose's lattice,
        // which sizes its buffers.
        Placement::Rays => {
            ch.require_closed(
                "--placement rays (GPU ray crossings; --placement random takes open meshes)",
            )?;
            lattice_in(&inside(), rest, spacing)
        }
    };
    if pts.is_empty() {
        // Its thinnest part holds about three at a third of its width.
        let (lo, hi) = super::super::character::check::bounds(rest);
        let fits = (hi - lo).min_element() / 3.0;
        return Err(Error::Model {
            path: ch.source.clone(),
            message: format!(
                "gives no control particles at spacing {spacing} (the mesh is smaller than the spacing): a spacing of {fits:.3e} or less (--fluid spacing or --control-spacing) would place some"
            ),
        });
    }
    Ok(pts)
}

/// Per control particle, the fraction of rest density that fluid filling the shape exactly
/// would have there: the poly6 sum over the control set (support `h`, the fluid's), each
/// particle standing for an equal share of the shape's `volume`. About 1 inside, 0.8 at a
/// flat surface (h = 2 spacings), less at edges and tips; at most 1. What `--control-deficit
/// shape` measures a control particle's deficit against.
pub fn fill(points: &[Vec3], volume: f32, h: f32) -> Vec<f32> {
    let grid = super::grid::Grid::new(points, |_| true, h);
    let share = volume / points.len().max(1) as f32;
    let poly6 = 315.0 / (64.0 * std::f32::consts::PI * h.powi(9));
    let h2 = h * h;
    points
        .iter()
        .map(|p| {
            let sum: f32 = grid
                .near(*p)
                .map(|k| p.distance_squared(points[k as usize]))
                .filter(|r2| *r2 < h2)
                .map(|r2| (h2 - r2).powi(3))
                .sum();
            (share * poly6 * sum).min(1.0)
        })
        .collect()
}
