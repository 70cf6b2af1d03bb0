//! Local thickness measured on the surface: from every vertex of the rest pose, the
//! distance along its inward normal to the opposite surface (rays through a uniform grid
//! of the triangles; on an open mesh, the far side of the solid its winding number fills:
//! clothes over a body are shells a few millimetres apart, and the next shell is not the
//! far side of the leg), gathered per region and taken at a low percentile, so that a few
//! thin details (an ear, a tail's tip) do not set the particle spacing while a leg does.
//! A region is a joint (the vertex's heaviest) of a skinned mesh; a static mesh has one
//! joint, so its regions are the cells of a coarse grid over its placed rest pose, named
//! by where they lie (+Y up, +Z the front, +X the character's left).
use super::model::Character;
use super::winding::FastWinding;
use crate::error::Result;
use glam::{Mat3, Vec3};

/// The region's thickness is this percentile of its vertices' thicknesses.
pub const PERCENTILE: f32 = 0.25;
/// Regions with fewer measured vertices are not reported.
pub const MIN_VERTICES: usize = 12;
/// The static-mesh grid: bands across X, up Y, along Z.
const GRID: [usize; 3] = [3, 4, 3];

/// A region of the surface and its thickness (the file's units).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Region {
    pub name: String,
    pub thickness: f32,
    pub vertices: usize,
}

/// Every region's thickness for the rest pose oriented by `orient` (the placement's
/// up axis and rotation; only names the static mesh's cells), thinnest first.
pub fn regions(ch: &Character, orient: Mat3) -> Result<Vec<Region>> {
    let (pos, nrm) = ch.skinned_at(&ch.rest_matrices(), crate::character::Skinning::Lbs)?;
    // An open mesh's rays start on the side its winding number calls inside.
    let open = (!ch.check.closed()).then(|| FastWinding::new(&pos, &ch.mesh.indices));
    let t = per_vertex(&pos, &nrm, &ch.mesh.indices, open.as_ref());
    let joints = ch.skeleton.joints.len();
    let (keys, names): (Vec<usize>, Vec<String>) = match joints > 1 {
        true => (
            (0..pos.len())
                .map(|v| ch.mesh.joints.get(v).map_or(0, |j| j[0] as usize))
                .collect(),
            (0..joints).map(|j| ch.joint_name(j)).collect(),
        ),
        false => cells(&pos, orient),
    };
    let mut by: Vec<Vec<f32>> = vec![Vec::new(); names.len()];
    for (v, d) in t.iter().enumerate() {
        if let (Some(d), Some(list)) = (d, by.get_mut(keys[v])) {
            list.push(*d);
        }
    }
    let mut out: Vec<Region> = by
        .into_iter()
        .zip(names)
        .filter(|(d, _)| d.len() >= MIN_VERTICES)
        .map(|(mut d, name)| {
            d.sort_by(f32::total_cmp);
            Region {
                name,
                thickness: d[((d.len() - 1) as f32 * PERCENTILE) as usize],
                vertices: d.len(),
            }
        })
        .collect();
    out.sort_by(|a, b| a.thickness.total_cmp(&b.thickness));
    Ok(out)
}

/// The static mesh's grid cell of every vertex (in the oriented pose) and the cells' names.
fn cells(pos: &[Vec3], orient: Mat3) -> (Vec<usize>, Vec<String>) {
    let p: Vec<Vec3> = pos.iter().map(|p| orient * *p).collect();
    let (lo, hi) = super::check::bounds(&p);
    let size = (hi - lo).max(Vec3::splat(1e-9));
    let band =
        |v: f32, k: usize| (((v - lo[k]) / size[k] * GRID[k] as f32) as usize).min(GRID[k] - 1);
    let keys = p
        .iter()
        .map(|v| band(v.x, 0) + GRID[0] * (band(v.y, 1) + GRID[1] * band(v.z, 2)))
        .collect();
    let (xs, ys, zs) = (
        ["right", "centre", "left"],
        ["bottom", "lower", "upper", "top"],
        ["back", "middle", "front"],
    );
    let mut names = Vec::new();
    for z in zs {
        for y in ys {
            for x in xs {
                names.push(format!("{y} {z} {x}"));
            }
        }
    }
    (keys, names)
}

/// Each vertex's thickness: the distance along -normal to the nearest other triangle
/// (None where the ray leaves the mesh without a hit: an open part). With `open` (an open
/// mesh's winding number), the ray goes to whichever side of the vertex is inside, to the
/// first surface past which the winding number calls the ray's point outside (layers it
/// crosses inside the solid do not stop it), and a vertex with neither side inside (a
/// sheet) has none.
pub fn per_vertex(
    pos: &[Vec3],
    nrm: &[Vec3],
    idx: &[u32],
    open: Option<&FastWinding>,
) -> Vec<Option<f32>> {
    let grid = Grid::new(pos, idx);
    let eps = 1e-4 * grid.diag;
    let probe = 1e-3 * grid.diag;
    // Just past a surface, to ask the winding number which side the ray is on.
    let past = 1e-4 * grid.diag;
    pos.iter()
        .zip(nrm)
        .map(|(p, n)| {
            let mut d = -n.normalize_or_zero();
            if let Some(w) = open {
                d = match (w.inside(*p + d * probe), w.inside(*p - d * probe)) {
                    (true, _) => d,
                    (false, true) => -d,
                    (false, false) => Vec3::ZERO,
                };
            }
            if d == Vec3::ZERO {
                return None;
            }
            match open {
                None => grid.cast(pos, idx, *p, d, eps, |_| true),
                Some(w) => grid.cast(pos, idx, *p, d, eps, |h| !w.inside(*p + d * (h + past))),
            }
        })
        .collect()
}

/// Triangles binned into a uniform grid over the mesh's bounds.
struct Grid {
    lo: Vec3,
    cell: Vec3,
    dims: [usize; 3],
    bins: Vec<Vec<u32>>,
    diag: f32,
}

impl Grid {
    fn new(pos: &[Vec3], idx: &[u32]) -> Self {
        let (lo, hi) = super::check::bounds(pos);
        let size = (hi - lo).max(Vec3::splat(1e-9));
        let tris = (idx.len() / 3).max(1) as f32;
        // About two triangles per cell on a surface: cells ~ tris along a face of cells.
        let edge = (size.x * size.y + size.y * size.z + size.z * size.x) / (2.0 * tris);
        let edge = edge.sqrt().max(size.max_element() / 256.0);
        let dims = [0, 1, 2].map(|k| ((size[k] / edge).ceil() as usize).clamp(1, 256));
        let cell = size / Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
        let mut g = Self {
            lo,
            cell,
            dims,
            bins: vec![Vec::new(); dims[0] * dims[1] * dims[2]],
            diag: size.length(),
        };
        for (t, tri) in idx.chunks_exact(3).enumerate() {
            let v = [0, 1, 2].map(|k| pos[tri[k] as usize]);
            let a = g.coord(v[0].min(v[1]).min(v[2]));
            let b = g.coord(v[0].max(v[1]).max(v[2]));
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        let i = g.index([x, y, z]);
                        g.bins[i].push(t as u32);
                    }
                }
            }
        }
        g
    }

    fn coord(&self, p: Vec3) -> [usize; 3] {
        let c = (p - self.lo) / self.cell;
        [0, 1, 2].map(|k| (c[k].max(0.0) as usize).min(self.dims[k] - 1))
    }

    fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The nearest hit beyond `eps` along the ray that `stop` accepts, hits offered in
    /// order of distance: the cells are walked in order (Amanatides & Woo) and a hit is
    /// offered once the walk has passed it (no nearer one can be met later).
    fn cast(
        &self,
        pos: &[Vec3],
        idx: &[u32],
        o: Vec3,
        d: Vec3,
        eps: f32,
        mut stop: impl FnMut(f32) -> bool,
    ) -> Option<f32> {
        let mut c = self.coord(o).map(|v| v as i64);
        let step = [0, 1, 2].map(|k| if d[k] >= 0.0 { 1i64 } else { -1 });
        let next = |k: usize, c: i64| {
            let edge = self.lo[k] + self.cell[k] * (c + (step[k] > 0) as i64) as f32;
            match d[k] == 0.0 {
                true => f32::INFINITY,
                false => (edge - o[k]) / d[k],
            }
        };
        let mut t_max = [0, 1, 2].map(|k| next(k, c[k]));
        let t_delta = [0, 1, 2].map(|k| (self.cell[k] / d[k].abs()).min(f32::INFINITY));
        // Hits met and not yet offered, farthest first; the last one offered (a triangle
        // binned in several cells is met again at the same distance, and not offered twice).
        let mut pending: Vec<f32> = Vec::new();
        let mut offered = f32::NAN;
        loop {
            let cell = self.index(c.map(|v| v as usize));
            for &t in &self.bins[cell] {
                let v = [0, 1, 2].map(|j| pos[idx[3 * t as usize + j] as usize]);
                if let Some(h) = hit(o, d, v).filter(|h| *h > eps) {
                    pending.push(h);
                }
            }
            pending.sort_by(|a, b| b.total_cmp(a));
            let k = (0..3)
                .min_by(|a, b| t_max[*a].total_cmp(&t_max[*b]))
                .unwrap_or(0);
            c[k] += step[k];
            let out = c[k] < 0 || c[k] >= self.dims[k] as i64;
            while let Some(&h) = pending.last() {
                if h > t_max[k] && !out {
                    break;
                }
                pending.pop();
                if h != offered && stop(h) {
                    return Some(h);
                }
                offered = h;
            }
            if out {
                return None;
            }
            t_max[k] += t_delta[k];
        }
    }
}

/// Möller–Trumbore: the ray parameter of the hit on triangle `v`, either side facing.
fn hit(o: Vec3, d: Vec3, v: [Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let w = d.dot(q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    Some(e2.dot(q) * inv)
}
