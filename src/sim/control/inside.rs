//! Inside tests on closed meshes. `InsideTest`: a ray along +x per query, crossings counted
//! with the sign of each triangle's facing (a winding number, so overlapping closed meshes
//! give their union), triangles binned by their y-z footprint on a grid, edge functions in
//! f64 from a slightly perturbed origin so a ray never runs exactly through an edge or
//! vertex (plain parity miscounts those). `winding_number`: the generalized winding number
//! (Jacobson et al. 2013) by brute force, the reference for the tests.
use glam::{DVec3, Vec3};

pub struct InsideTest {
    tris: Vec<[DVec3; 3]>,
    /// y-z grid: origin, cell size, dimensions, and per cell the triangles overlapping it.
    lo: [f64; 2],
    cell: [f64; 2],
    dims: [usize; 2],
    cells: Vec<Vec<u32>>,
    /// Origin perturbation (y, z): irrational multiples of the mesh size.
    eps: [f64; 2],
}

impl InsideTest {
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
    let mut sum = 0.0;
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3() - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}
