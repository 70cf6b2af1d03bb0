//! Marching cubes on the CPU: a scalar grid, the surface where it crosses `iso` with one
//! vertex per crossed grid edge (shared by the cells around it, so the mesh is welded and
//! closed wherever the grid's boundary is outside), normals from the grid's gradient.
use super::table::{corner, table, EDGES};
use std::collections::HashMap;

/// Values at the nodes of a regular grid, x fastest.
pub struct Grid {
    pub origin: [f32; 3],
    pub cell: f32,
    pub dims: [usize; 3],
    pub values: Vec<f32>,
}

impl Grid {
    fn at(&self, i: [usize; 3]) -> f32 {
        self.values[(i[2] * self.dims[1] + i[1]) * self.dims[0] + i[0]]
    }

    /// The gradient at a node by central differences (one-sided at the boundary).
    fn gradient(&self, i: [usize; 3]) -> [f32; 3] {
        let mut g = [0.0; 3];
        for (k, gk) in g.iter_mut().enumerate() {
            let (mut lo, mut hi) = (i, i);
            lo[k] = i[k].saturating_sub(1);
            hi[k] = (i[k] + 1).min(self.dims[k] - 1);
            let span = (hi[k] - lo[k]).max(1) as f32 * self.cell;
            *gk = (self.at(hi) - self.at(lo)) / span;
        }
        g
    }
}

/// Triangles with welded vertices and unit normals (facing lower values: out of the fluid).
#[derive(Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Enclosed volume by the divergence theorem (positive for outward triangles).
    pub fn volume(&self) -> f64 {
        let p = |i: u32| self.positions[i as usize].map(|v| v as f64);
        self.indices
            .chunks(3)
            .map(|t| {
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                let cross = [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ];
                (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
            })
            .sum()
    }

    /// Directed edges without exactly one opposite partner (0: closed and consistently
    /// oriented).
    pub fn open_edges(&self) -> usize {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in self.indices.chunks(3) {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        (directed.iter())
            .filter(|(&(a, b), &n)| n != 1 || directed.get(&(b, a)) != Some(&1))
            .count()
    }
}

/// The surface where `grid` crosses `iso`, the side above `iso` inside.
pub fn march(grid: &Grid, iso: f32) -> Mesh {
    let cases = table();
    let mut mesh = Mesh::default();
    // Vertex per grid edge: (lower node's index, axis).
    let mut made: HashMap<(usize, usize), u32> = HashMap::new();
    let [nx, ny, nz] = grid.dims;
    for z in 0..nz.saturating_sub(1) {
        for y in 0..ny.saturating_sub(1) {
            for x in 0..nx.saturating_sub(1) {
                let node = |c: usize| {
                    let o = corner(c);
                    [x + o[0], y + o[1], z + o[2]]
                };
                let case = (0..8).fold(0, |m, c| m | ((grid.at(node(c)) >= iso) as usize) << c);
                for tri in &cases[case] {
                    let mut ids = [0u32; 3];
                    for (slot, &e) in ids.iter_mut().zip(tri) {
                        let (a, b) = (node(EDGES[e].0), node(EDGES[e].1));
                        let axis = (0..3).find(|&k| a[k] != b[k]).unwrap();
                        let low = if a[axis] < b[axis] { a } else { b };
                        let key = ((low[2] * ny + low[1]) * nx + low[0], axis);
                        *slot = *made
                            .entry(key)
                            .or_insert_with(|| vertex(grid, iso, a, b, &mut mesh));
                    }
                    mesh.indices.extend(ids);
                }
            }
        }
    }
    mesh
}

/// The crossing on the edge between nodes a and b, added to `mesh`.
fn vertex(grid: &Grid, iso: f32, a: [usize; 3], b: [usize; 3], mesh: &mut Mesh) -> u32 {
    let (va, vb) = (grid.at(a), grid.at(b));
    let t = ((iso - va) / (vb - va)).clamp(0.0, 1.0);
    let pos = |i: [usize; 3], k: usize| grid.origin[k] + i[k] as f32 * grid.cell;
    let (ga, gb) = (grid.gradient(a), grid.gradient(b));
    let mut p = [0.0; 3];
    let mut n = [0.0; 3];
    for k in 0..3 {
        p[k] = pos(a, k) + t * (pos(b, k) - pos(a, k));
        n[k] = -(ga[k] + t * (gb[k] - ga[k]));
    }
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-20);
    mesh.positions.push(p);
    mesh.normals.push(n.map(|v| v / l));
    (mesh.positions.len() - 1) as u32
}

/// The SPH density of particles `pos` (poly6 kernel, smoothing length `h`, mass `mass`)
/// over `rest`, on a grid of `cell` covering them with a margin of h plus a cell, so the
/// boundary nodes are outside and the surface is closed.
pub fn density_grid(pos: &[[f32; 3]], h: f32, mass: f32, rest: f32, cell: f32) -> Grid {
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for p in pos {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let margin = h + cell;
    let origin = lo.map(|v| v - margin);
    let dims = [0, 1, 2].map(|k| ((hi[k] + margin - origin[k]) / cell).ceil() as usize + 1);
    density_on(pos, (h, mass, rest), origin, cell, dims)
}

/// As `density_grid`, on the grid of `dims` nodes from `origin` (the GPU's, for instance).
pub fn density_on(
    pos: &[[f32; 3]],
    (h, mass, rest): (f32, f32, f32),
    origin: [f32; 3],
    cell: f32,
    dims: [usize; 3],
) -> Grid {
    let mut values = vec![0.0f32; dims[0] * dims[1] * dims[2]];
    let (h2, k) = (h * h, 315.0 / (64.0 * std::f32::consts::PI * h.powi(9)));
    let reach = (h / cell).ceil() as isize;
    for p in pos {
        let c = [0, 1, 2].map(|a| ((p[a] - origin[a]) / cell).round() as isize);
        for dz in -reach..=reach {
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let i = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if (0..3).any(|a| i[a] < 0 || i[a] >= dims[a] as isize) {
                        continue;
                    }
                    let d2: f32 = (0..3)
                        .map(|a| (origin[a] + i[a] as f32 * cell - p[a]).powi(2))
                        .sum();
                    if d2 < h2 {
                        let idx =
                            (i[2] as usize * dims[1] + i[1] as usize) * dims[0] + i[0] as usize;
                        values[idx] += mass * k * (h2 - d2).powi(3) / rest;
                    }
                }
            }
        }
    }
    Grid {
        origin,
        cell,
        dims,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_closes_and_faces_out() {
        // Each case alone in a 2x2x2 cell, padded by a layer outside: closed, outward.
        for case in 0..256usize {
            let dims = [4, 4, 4];
            let mut values = vec![0.0f32; 64];
            for c in 0..8 {
                let o = corner(c);
                values[((o[2] + 1) * 4 + o[1] + 1) * 4 + o[0] + 1] =
                    if case >> c & 1 == 1 { 1.0 } else { 0.0 };
            }
            let g = Grid {
                origin: [0.0; 3],
                cell: 1.0,
                dims,
                values,
            };
            let m = march(&g, 0.5);
            assert_eq!(m.open_edges(), 0, "case {case}");
            let inside = (0..8).filter(|c| case >> c & 1 == 1).count();
            assert!(
                (m.volume() > 0.0) == (inside > 0),
                "case {case}: volume {}",
                m.volume()
            );
        }
    }

    #[test]
    fn a_sphere_has_its_volume() {
        let (n, cell, r) = (40usize, 0.05f32, 0.7f32);
        let c = n as f32 * cell * 0.5;
        let values = (0..n * n * n)
            .map(|i| {
                let p = [i % n, i / n % n, i / (n * n)].map(|v| v as f32 * cell - c);
                r - (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()
            })
            .collect();
        let g = Grid {
            origin: [-c; 3],
            cell,
            dims: [n; 3],
            values,
        };
        let m = march(&g, 0.0);
        assert_eq!(m.open_edges(), 0);
        let want = 4.0 / 3.0 * std::f64::consts::PI * (r as f64).powi(3);
        assert!(
            (m.volume() / want - 1.0).abs() < 0.01,
            "{} vs {want}",
            m.volume()
        );
        // Normals point out of the sphere.
        for (p, nrm) in m.positions.iter().zip(&m.normals) {
            let d = p[0] * nrm[0] + p[1] * nrm[1] + p[2] * nrm[2];
            assert!(d > 0.9 * r, "normal {nrm:?} at {p:?}");
        }
    }

    #[test]
    fn a_block_of_particles_has_their_volume() {
        // 12^3 particles on a lattice of spacing s at rest density: volume (12 s)^3.
        let (s, rest) = (0.02f32, 1000.0f32);
        let mut pos = Vec::new();
        for z in 0..12 {
            for y in 0..12 {
                for x in 0..12 {
                    pos.push([x as f32 * s, y as f32 * s, z as f32 * s]);
                }
            }
        }
        let g = density_grid(&pos, 2.0 * s, rest * s * s * s, rest, 0.5 * s);
        let m = march(&g, 0.5);
        assert_eq!(m.open_edges(), 0);
        let want = (12.0 * s as f64).powi(3);
        let ratio = m.volume() / want;
        assert!(
            (ratio - 1.0).abs() < 0.10,
            "volume {} vs {want} (x{ratio:.3})",
            m.volume()
        );
    }
}
