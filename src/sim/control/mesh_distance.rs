//! Unsigned distance from points to a triangle mesh: triangles binned on a uniform grid by
//! their bounding boxes, searched in growing shells of cells until no nearer triangle can
//! lie beyond the shell (the fidelity metrics' surface distance).
use glam::{IVec3, Vec3};
use std::collections::HashMap;

/// Distance from `p` to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
pub fn tri_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    (p - tri_closest(p, a, b, c).0).length()
}

/// The point of triangle (a, b, c) nearest `p`, and its barycentric coordinates (Ericson,
/// Real-Time Collision Detection 5.1.5).
pub fn tri_closest(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f32; 3]) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

pub struct SurfaceDistance {
    tris: Vec<[Vec3; 3]>,
    cell: f32,
    cells: HashMap<IVec3, Vec<u32>>,
    /// Cell range of the whole mesh: shells past it hold nothing new.
    lo: IVec3,
    hi: IVec3,
}

impl SurfaceDistance {
    /// Triangles `indices` over `positions`, binned in cells of `cell` metres.
    pub fn new(positions: &[Vec3], indices: &[u32], cell: f32) -> Self {
        let tris: Vec<[Vec3; 3]> = indices
            .chunks_exact(3)
            .map(|t| [0, 1, 2].map(|k| positions[t[k] as usize]))
            .collect();
        let key = |p: Vec3| (p / cell).floor().as_ivec3();
        let mut cells: HashMap<IVec3, Vec<u32>> = HashMap::new();
        let (mut lo, mut hi) = (IVec3::MAX, IVec3::MIN);
        for (i, t) in tris.iter().enumerate() {
            let a = key(t[0].min(t[1]).min(t[2]));
            let b = key(t[0].max(t[1]).max(t[2]));
            lo = lo.min(a);
            hi = hi.max(b);
            for z in a.z..=b.z {
                for y in a.y..=b.y {
                    for x in a.x..=b.x {
                        cells.entry(IVec3::new(x, y, z)).or_default().push(i as u32);
                    }
                }
            }
        }
        Self {
            tris,
            cell,
            cells,
            lo,
            hi,
        }
    }

    /// Distance from `p` to the nearest triangle (infinity for an empty mesh).
    pub fn distance(&self, p: Vec3) -> f32 {
        self.nearest(p).map_or(f32::INFINITY, |n| n.0)
    }

    /// The nearest triangle to `p`: (distance, its index, the barycentric coordinates of
    /// its point nearest `p`); the first triangle met among equals. None for an empty mesh.
    pub fn nearest(&self, p: Vec3) -> Option<(f32, u32, [f32; 3])> {
        let c = (p / self.cell).floor().as_ivec3();
        let mut best: Option<(f32, u32, [f32; 3])> = None;
        // Shell r covers every point within r cells of p's cell: a triangle not met yet
        // is farther than r cells (r * cell) from p.
        let reach = (c - self.lo).abs().max((c - self.hi).abs()).max_element();
        for r in 0..=reach.max(0) {
            for z in -r..=r {
                for y in -r..=r {
                    for x in -r..=r {
                        if x.abs().max(y.abs()).max(z.abs()) != r {
                            continue;
                        }
                        let Some(list) = self.cells.get(&(c + IVec3::new(x, y, z))) else {
                            continue;
                        };
                        for &t in list {
                            let [a, b, cc] = self.tris[t as usize];
                            let (q, bary) = tri_closest(p, a, b, cc);
                            let d = (p - q).length();
                            if best.is_none_or(|b| d < b.0) {
                                best = Some((d, t, bary));
                            }
                        }
                    }
                }
            }
            if best.is_some_and(|b| b.0 <= r as f32 * self.cell) {
                break;
            }
        }
        best
    }
}
