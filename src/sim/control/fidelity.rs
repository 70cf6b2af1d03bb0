//! Shape-fidelity metrics of a liquid character, on the CPU from one frame's particles and
//! the skinned target (definitions in the README, "Fidelity metrics"):
//! - `fill`: target interior voxels (centres inside the mesh, at the particle spacing) where
//!   the fluid's SPH density is at least half the rest density;
//! - `iou`: that occupancy against the interior, over the voxels of the target's box grown
//!   by two smoothing lengths (water elsewhere does not count, water beside the shape does);
//! - `spray`: mass fraction of fluid that is isolated (fewer than `SPRAY_NEIGHBORS`
//!   neighbours within h), off the floor and more than 2h from the interior (Ihmsen 2012);
//! - `surface_p95`: 95th percentile distance of the surface particles in the box to the
//!   mesh, in spacings;
//! - `density_in_shape`: mean density of the fluid inside over rest density;
//! - `speed_excess`: the fastest fluid in the box minus the fastest skin point.
use super::grid::Grid;
use super::inside::InsideTest;
use super::mesh_distance::SurfaceDistance;
use crate::character::check;
use glam::{IVec3, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

/// Fewer neighbours than this within h: isolated (spray when airborne and away).
pub const SPRAY_NEIGHBORS: usize = 5;

/// The fluid of one frame: positions, velocities, SPH densities, and whether each
/// particle is of the controlled groups.
pub struct Frame<'a> {
    pub pos: &'a [Vec3],
    pub vel: &'a [Vec3],
    pub rho: &'a [f32],
    pub controlled: &'a [bool],
}

/// The fluid's constants the metrics need.
#[derive(Clone, Copy, Debug)]
pub struct Fluid {
    pub h: f32,
    pub mass: f32,
    pub rest_density: f32,
    /// Voxel size (the particle spacing).
    pub spacing: f32,
    /// The floor's height (the domain's bottom).
    pub floor: f32,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Fidelity {
    pub fill: f64,
    pub iou: f64,
    pub spray: f64,
    pub surface_p95: f64,
    /// None: no fluid inside.
    pub density_in_shape: Option<f64>,
    pub speed_excess: f64,
}

/// Voxel counts over a box: the target's interior, how much of it the fluid fills, and
/// fluid occupancy outside it.
struct Voxels {
    interior: usize,
    filled: usize,
    occupied_out: usize,
    interior_set: HashSet<IVec3>,
}

/// `dims` voxels of side `s` from `lo`, each classified by its centre.
fn voxels(
    inside: &InsideTest,
    occupied: impl Fn(Vec3) -> bool,
    lo: Vec3,
    dims: IVec3,
    s: f32,
) -> Voxels {
    let (mut interior, mut filled, mut occupied_out) = (0usize, 0usize, 0usize);
    let mut interior_set = HashSet::new();
    let (centres, ins) = inside.voxels(lo, dims.as_uvec3(), s);
    let (dx, dy) = (dims.x as usize, dims.y as usize);
    for (i, (c, is_in)) in centres.into_iter().zip(ins).enumerate() {
        let v = IVec3::new(
            (i % dx) as i32,
            (i / dx % dy) as i32,
            (i / (dx * dy)) as i32,
        );
        let occupied = occupied(c);
        if is_in {
            interior += 1;
            interior_set.insert(v);
            filled += occupied as usize;
        } else {
            occupied_out += occupied as usize;
        }
    }
    Voxels {
        interior,
        filled,
        occupied_out,
        interior_set,
    }
}

/// The metrics of `frame` against the target `mesh` (positions, triangles; `inside` its
/// inside test), whose skin points move at most `skin_speed` m/s.
pub fn measure(
    frame: &Frame,
    (mesh, inside): ((&[Vec3], &[u32]), &InsideTest),
    skin_speed: f32,
    f: &Fluid,
) -> Fidelity {
    let (h, s) = (f.h, f.spacing);
    let h2 = h * h;
    let poly6 = 315.0 / (64.0 * std::f32::consts::PI * h.powi(9));
    let controlled = |i: usize| frame.controlled[i];
    let grid = Grid::new(frame.pos, controlled, h);
    let density = |x: Vec3| -> f32 {
        let sum: f32 = grid
            .near(x)
            .map(|j| (frame.pos[j as usize] - x).length_squared())
            .filter(|r2| *r2 < h2)
            .map(|r2| (h2 - r2).powi(3))
            .sum();
        f.mass * poly6 * sum
    };
    let (mlo, mhi) = check::bounds(mesh.0);
    let (lo, hi) = (mlo - Vec3::splat(2.0 * h), mhi + Vec3::splat(2.0 * h));
    let in_box = |p: Vec3| p.cmpge(lo).all() && p.cmple(hi).all();
    // Voxels of the grown box: target interior and fluid occupancy.
    let dims = ((hi - lo) / s).ceil().as_ivec3().max(IVec3::ONE);
    let occupied = |c: Vec3| density(c) >= 0.5 * f.rest_density;
    let Voxels {
        interior,
        filled,
        occupied_out,
        interior_set,
    } = voxels(inside, occupied, lo, dims, s);
    let fill = filled as f64 / interior.max(1) as f64;
    let iou = filled as f64 / (interior + occupied_out).max(1) as f64;
    // Neighbour counts within h over every live particle (spray counts all the fluid).
    let all = Grid::new(frame.pos, |_| true, h);
    let neighbours = |i: usize| {
        let p = frame.pos[i];
        all.near(p)
            .filter(|&j| j as usize != i && (frame.pos[j as usize] - p).length_squared() < h2)
            .count()
    };
    let reach = (2.0 * h / s).ceil() as i32;
    let near_interior = |p: Vec3| {
        let v = ((p - lo) / s).floor().as_ivec3();
        (-reach..=reach).any(|z| {
            (-reach..=reach).any(|y| {
                (-reach..=reach).any(|x| {
                    let w = v + IVec3::new(x, y, z);
                    interior_set.contains(&w)
                        && (lo + (w.as_vec3() + 0.5) * s - p).length() <= 2.0 * h
                })
            })
        })
    };
    let surface = SurfaceDistance::new(mesh.0, mesh.1, 2.0 * s);
    // A full neighbourhood at rest spacing holds 4/3 pi (h/s)^3 - 1 particles; a surface
    // particle sees about half to two thirds of that.
    let full = 4.0 / 3.0 * std::f32::consts::PI * (h / s).powi(3) - 1.0;
    let (mut spray, mut dists, mut speed, mut rho_in, mut n_in) =
        (0usize, Vec::new(), 0f32, 0f64, 0usize);
    for (i, &p) in frame.pos.iter().enumerate() {
        let n = neighbours(i);
        let boxed = in_box(p);
        if n < SPRAY_NEIGHBORS && p.y > f.floor + h && !near_interior(p) {
            spray += 1;
        }
        if !frame.controlled[i] || !boxed {
            continue;
        }
        speed = speed.max(frame.vel[i].length());
        if (n as f32) < 0.66 * full {
            dists.push(surface.distance(p) / s);
        }
        if inside.inside(p) {
            rho_in += frame.rho[i] as f64;
            n_in += 1;
        }
    }
    dists.sort_by(f32::total_cmp);
    let p95 = match dists.len() {
        0 => 0.0,
        n => dists[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1] as f64,
    };
    Fidelity {
        fill,
        iou,
        spray: spray as f64 / frame.pos.len().max(1) as f64,
        surface_p95: p95,
        density_in_shape: (n_in > 0).then(|| rho_in / n_in as f64 / f.rest_density as f64),
        speed_excess: (speed - skin_speed) as f64,
    }
}
