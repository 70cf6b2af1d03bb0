//! Mesh checks after welding by position: boundary and non-manifold edges, connected
//! components, signed volume; area-weighted normals over welded vertices.
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshCheck {
    pub welded_vertices: usize,
    /// Edges used by one triangle.
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Triangles with two welded corners equal (ignored by the edge counts).
    pub degenerate_triangles: usize,
    pub components: usize,
    /// Sum of signed tetrahedron volumes: positive for an outward-facing closed mesh.
    pub signed_volume: f64,
}

impl MeshCheck {
    pub fn closed(&self) -> bool {
        self.boundary_edges == 0 && self.nonmanifold_edges == 0
    }

    /// The counts for an error or report line.
    pub fn describe(&self) -> String {
        format!(
            "{} boundary and {} non-manifold edges, {} components",
            self.boundary_edges, self.nonmanifold_edges, self.components
        )
    }
}

/// Welded index of every vertex: positions equal to 1e-6 of the bounding-box diagonal
/// (snapped to that grid) share one.
pub fn weld(positions: &[Vec3]) -> (Vec<u32>, usize) {
    let (lo, hi) = bounds(positions);
    let tol = ((hi - lo).length() * 1e-6).max(f32::MIN_POSITIVE) as f64;
    let mut map: HashMap<[i64; 3], u32> = HashMap::with_capacity(positions.len());
    let remap = positions
        .iter()
        .map(|p| {
            let q = (p.as_dvec3() - lo.as_dvec3()) / tol;
            let key = [q.x.round() as i64, q.y.round() as i64, q.z.round() as i64];
            let next = map.len() as u32;
            *map.entry(key).or_insert(next)
        })
        .collect();
    (remap, map.len())
}

pub fn bounds(positions: &[Vec3]) -> (Vec3, Vec3) {
    positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

/// Signed volume (f64) of the triangles `indices` over `positions`.
pub fn signed_volume(positions: &[Vec3], indices: &[u32]) -> f64 {
    indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

pub fn check(positions: &[Vec3], indices: &[u32]) -> MeshCheck {
    let (remap, welded) = weld(positions);
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(indices.len());
    let mut parent: Vec<u32> = (0..welded as u32).collect();
    fn find(p: &mut [u32], mut i: u32) -> u32 {
        while p[i as usize] != i {
            p[i as usize] = p[p[i as usize] as usize];
            i = p[i as usize];
        }
        i
    }
    let mut degenerate = 0;
    let mut used = vec![false; welded];
    for t in indices.chunks_exact(3) {
        let w = [0, 1, 2].map(|k| remap[t[k] as usize]);
        for &v in &w {
            used[v as usize] = true;
        }
        let (a, b) = (find(&mut parent, w[0]), find(&mut parent, w[1]));
        parent[a as usize] = b;
        let (b, c) = (find(&mut parent, w[1]), find(&mut parent, w[2]));
        parent[b as usize] = c;
        if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
            degenerate += 1;
            continue;
        }
        for k in 0..3 {
            let (i, j) = (w[k], w[(k + 1) % 3]);
            *edges.entry((i.min(j), i.max(j))).or_default() += 1;
        }
    }
    let components = (0..welded as u32)
        .filter(|&i| used[i as usize] && find(&mut parent, i) == i)
        .count();
    MeshCheck {
        welded_vertices: welded,
        boundary_edges: edges.values().filter(|&&c| c == 1).count(),
        nonmanifold_edges: edges.values().filter(|&&c| c > 2).count(),
        degenerate_triangles: degenerate,
        components,
        signed_volume: signed_volume(positions, indices),
    }
}

/// Area-weighted vertex normals, accumulated over welded vertices so seams get one normal.
pub fn area_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let (remap, welded) = weld(positions);
    let mut acc = vec![DVec3::ZERO; welded];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3());
        let n = (b - a).cross(c - a); // length = twice the area
        for k in 0..3 {
            acc[remap[t[k] as usize] as usize] += n;
        }
    }
    remap
        .iter()
        .map(|&w| acc[w as usize].normalize_or_zero().as_vec3())
        .collect()
}

/// Reverse every triangle's winding.
pub fn flip(indices: &mut [u32]) {
    for t in indices.chunks_exact_mut(3) {
        t.swap(1, 2);
    }
}
