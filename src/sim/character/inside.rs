//! Inside tests. `InsideTest` picks one by the mesh: on a closed mesh, `Crossings` (exact,
//! the answers every closed character has always had); on an open or many-part one, the
//! generalized winding number above 1/2 (`winding::FastWinding`, robust to holes,
//! overlaps, non-manifold edges and soups).
//!
//! `Crossings`: a ray along +x per query, crossings counted with the sign of each
//! triangle's facing (a winding number, so overlapping closed meshes give their union),
//! triangles binned by their y-z footprint on a grid, edge functions in f64 from a
//! slightly perturbed origin so a ray never runs exactly through an edge or vertex (plain
//! parity miscounts those). `winding_number`: the generalized winding number (Jacobson et
//! al. 2013) by brute force, the reference for the tests.
use super::winding::FastWinding;
use glam::{DVec3, Vec3};

/// Inside a mesh, by the test that suits it.
pub enum InsideTest {
    /// A closed mesh: signed ray crossings.
    Closed(Crossings),
    /// An open mesh: the generalized winding number above 1/2.
    Open(FastWinding),
}

impl InsideTest {
    /// Crossings when the mesh is closed (after welding), else the winding number.
    pub fn new(positions: &[Vec3], indices: &[u32]) -> Self {
        let closed = super::check::check(positions, indices).closed();
        Self::of(positions, indices, closed)
    }

    /// Crossings when `closed`, else the winding number: a character's test, decided once
    /// by its own check at the rest pose (welding posed vertices could decide otherwise on
    /// some frame).
    pub fn of(positions: &[Vec3], indices: &[u32], closed: bool) -> Self {
        match closed {
            true => Self::Closed(Crossings::new(positions, indices)),
            false => Self::Open(FastWinding::new(positions, indices)),
        }
    }

    pub fn is_open(&self) -> bool {
        matches!(self, Self::Open(_))
    }

    pub fn inside(&self, p: Vec3) -> bool {
        match self {
            Self::Closed(c) => c.inside(p),
            Self::Open(w) => w.inside(p),
        }
    }

    /// `inside` of every point, on every core (the winding number's queries are the cost
    /// of voxelising an open character).
    pub fn inside_all(&self, points: &[Vec3]) -> Vec<bool> {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let chunk = points.len().div_ceil(threads).max(4096);
        let mut out = vec![false; points.len()];
        std::thread::scope(|s| {
            for (p, o) in points.chunks(chunk).zip(out.chunks_mut(chunk)) {
                s.spawn(move || {
                    for (p, o) in p.iter().zip(o) {
                        *o = self.inside(*p);
                    }
                });
            }
        });
        out
    }

    /// The centres of `dims` voxels of side `s` from `lo` (x fastest) and which are inside.
    pub fn voxels(&self, lo: Vec3, dims: glam::UVec3, s: f32) -> (Vec<Vec3>, Vec<bool>) {
        let mut centres = Vec::with_capacity(dims.x as usize * dims.y as usize * dims.z as usize);
        for k in 0..dims.z {
            for j in 0..dims.y {
                for i in 0..dims.x {
                    centres.push(lo + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * s);
                }
            }
        }
        let inside = self.inside_all(&centres);
        (centres, inside)
    }
}

pub struct Crossings {
    tris: Vec<[DVec3; 3]>,
    /// y-z grid: origin, cell size, dimensions, and per cell the triangles overlapping it.
    lo: [f64; 2],
    cell: [f64; 2],
    dims: [usize; 2],
    cells: Vec<Vec<u32>>,
    /// Origin perturbation (y, z): irrational multiples of the mesh size.
    eps: [f64; 2],
}

impl Crossings {
    pub fn new(positions: &[Vec3], indices: &[u32]) -> Self {
        let tris: Vec<[DVec3; 3]> = indices
            .chunks_exact(3)
            .map(|t| [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3()))
            .collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for t in &tris {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        let size = (hi - lo).max(DVec3::splat(1e-9));
        let side = ((tris.len() as f64).sqrt().ceil() as usize).clamp(1, 512);
        let dims = [side, side];
        let cell = [size.y / side as f64, size.z / side as f64];
        let mut cells = vec![Vec::new(); side * side];
        for (i, t) in tris.iter().enumerate() {
            let (mut a, mut b) = ([usize::MAX; 2], [0usize; 2]);
            for p in t {
                for (k, v) in [p.y, p.z].into_iter().enumerate() {
                    let lo_k = [lo.y, lo.z][k];
                    let c = (((v - lo_k) / cell[k]).floor().max(0.0) as usize).min(side - 1);
                    a[k] = a[k].min(c);
                    b[k] = b[k].max(c);
                }
            }
            for y in a[0]..=b[0] {
                for z in a[1]..=b[1] {
                    cells[y * side + z].push(i as u32);
                }
            }
        }
        let diag = size.length();
        Self {
            tris,
            lo: [lo.y, lo.z],
            cell,
            dims,
            cells,
            eps: [
                diag * 1.1e-9 * std::f64::consts::SQRT_2,
                diag * 0.7e-9 * std::f64::consts::PI,
            ],
        }
    }

    /// Signed crossings of the +x ray from `p`: the winding number of the mesh about `p`.
    pub fn winding(&self, p: Vec3) -> i32 {
        let (py, pz) = (p.y as f64 + self.eps[0], p.z as f64 + self.eps[1]);
        let px = p.x as f64;
        let cy = ((py - self.lo[0]) / self.cell[0]).floor();
        let cz = ((pz - self.lo[1]) / self.cell[1]).floor();
        if cy < 0.0 || cz < 0.0 || cy >= self.dims[0] as f64 || cz >= self.dims[1] as f64 {
            return 0;
        }
        let mut w = 0;
        for &i in &self.cells[cy as usize * self.dims[1] + cz as usize] {
            let [a, b, c] = self.tris[i as usize];
            // Edge functions of the y-z projection about the ray (Woop et al. 2013, with the
            // ray along x no shear is needed).
            let (ay, az, by, bz, cy, cz) =
                (a.y - py, a.z - pz, b.y - py, b.z - pz, c.y - py, c.z - pz);
            let u = cy * bz - cz * by;
            let v = ay * cz - az * cy;
            let wv = by * az - bz * ay;
            if (u < 0.0 || v < 0.0 || wv < 0.0) && (u > 0.0 || v > 0.0 || wv > 0.0) {
                continue;
            }
            let det = u + v + wv;
            if det == 0.0 {
                continue;
            }
            let t = (u * (a.x - px) + v * (b.x - px) + wv * (c.x - px)) / det;
            if t > 0.0 {
                w += if det > 0.0 { 1 } else { -1 };
            }
        }
        w
    }

    pub fn inside(&self, p: Vec3) -> bool {
        self.winding(p) != 0
    }
}

/// Generalized winding number: the solid angles of all triangles about `p` over 4 pi
/// (1 inside a closed outward mesh, 0 outside).
pub fn winding_number(positions: &[Vec3], indices: &[u32], p: Vec3) -> f64 {
    let p = p.as_dvec3();
    (indices.chunks_exact(3))
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3() - p);
            super::winding::triangle_winding(a, b, c)
        })
        .sum()
}

/// Voxels a volume may take: a finer side is coarsened to hold it.
const MAX_VOXELS: f64 = 16.0 * 1024.0 * 1024.0;

/// The volume a mesh holds: a closed one's signed volume (exact); an open one's voxels of
/// side `side` (coarsened to at most `MAX_VOXELS`) inside by the winding number, with the
/// voxel count and side. `closed` is the mesh's own check.
pub fn volume(
    positions: &[Vec3],
    indices: &[u32],
    side: f32,
    closed: bool,
) -> (f64, Option<(usize, f64)>) {
    if closed {
        return (super::check::signed_volume(positions, indices).abs(), None);
    }
    let (lo, hi) = super::check::bounds(positions);
    let size = (hi - lo).as_dvec3();
    if !(size.max_element() > 0.0 && size.is_finite()) {
        return (0.0, Some((0, side as f64)));
    }
    let at = |s: f64| (size / s).ceil().max(DVec3::ONE);
    let mut s = (side as f64).max(size.max_element() * 1e-6);
    let n = at(s);
    if n.x * n.y * n.z > MAX_VOXELS {
        s *= (n.x * n.y * n.z / MAX_VOXELS).cbrt() * 1.01;
    }
    let dims = at(s).as_uvec3();
    let open = InsideTest::of(positions, indices, false);
    let n = open
        .voxels(lo, dims, s as f32)
        .1
        .iter()
        .filter(|i| **i)
        .count();
    (n as f64 * s.powi(3), Some((n, s)))
}
