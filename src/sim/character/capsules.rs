//! The character as capsules, one per bone: the procedural characters' own, or fitted to
//! a loaded skin (a joint's capsule runs from its head towards its child's head, its
//! radius a low percentile of its vertices' distances, so it stays inside the surface).
//! Posed by the joints' skinning matrices, they make the character a fluid collider.
use super::model::{Character, Mesh, Skeleton};
use glam::{Mat4, Vec3};

/// A capsule in the bind pose, carried by `joint`'s skinning matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoneCapsule {
    pub joint: usize,
    pub a: Vec3,
    pub b: Vec3,
    pub r: f32,
}

/// A capsule in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PosedCapsule {
    pub a: Vec3,
    pub b: Vec3,
    pub r: f32,
}

impl BoneCapsule {
    /// Distance from `p` to the capsule's axis segment.
    pub fn axis_distance(&self, p: Vec3) -> f32 {
        let ab = self.b - self.a;
        let s = ((p - self.a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
        (p - (self.a + ab * s)).length()
    }

    /// Posed by the skinning matrices `mats` (placement included); the radius scales with
    /// the joint matrix's mean scale.
    pub fn posed(&self, mats: &[Mat4]) -> PosedCapsule {
        let m = mats[self.joint];
        let scale = m.determinant().abs().cbrt();
        PosedCapsule {
            a: m.transform_point3(self.a),
            b: m.transform_point3(self.b),
            r: self.r * scale,
        }
    }
}

/// Fraction of a bone's vertices the fitted radius leaves outside the capsule.
const RADIUS_PERCENTILE: f32 = 0.3;
/// Bones with fewer vertices get no capsule.
const MIN_VERTICES: usize = 6;

/// The character's capsules: its own (procedural) or fitted to its skin.
pub fn of(ch: &Character) -> Vec<BoneCapsule> {
    if !ch.capsules.is_empty() {
        return ch.capsules.clone();
    }
    fit(&ch.mesh, &ch.skeleton)
}

/// One capsule per joint that dominates at least MIN_VERTICES vertices: from the joint's
/// bind-pose head to the head of the child joint nearest its vertices' centroid (or, for
/// a leaf, along the centroid's direction to its farthest vertex), radius the
/// RADIUS_PERCENTILE distance of those vertices to the segment.
pub fn fit(mesh: &Mesh, skel: &Skeleton) -> Vec<BoneCapsule> {
    let heads: Vec<Vec3> = skel
        .joints
        .iter()
        .map(|j| j.inverse_bind.inverse().w_axis.truncate())
        .collect();
    let mut owned: Vec<Vec<Vec3>> = vec![Vec::new(); skel.joints.len()];
    for (v, p) in mesh.positions.iter().enumerate() {
        if let Some(j) = mesh.joints.get(v).map(|j| j[0] as usize) {
            if j < owned.len() && mesh.weights[v][0] > 0.0 {
                owned[j].push(*p);
            }
        }
    }
    let mut out = Vec::new();
    for (j, verts) in owned.iter().enumerate() {
        if verts.len() < MIN_VERTICES {
            continue;
        }
        let a = heads[j];
        let centroid = verts.iter().copied().sum::<Vec3>() / verts.len() as f32;
        let node = skel.joints[j].node;
        let children = skel
            .joints
            .iter()
            .enumerate()
            .filter(|(_, c)| skel.nodes[c.node].parent == Some(node))
            .map(|(k, _)| heads[k]);
        let seg_dist = |b: Vec3| {
            BoneCapsule {
                joint: j,
                a,
                b,
                r: 0.0,
            }
            .axis_distance(centroid)
        };
        let b = children
            .filter(|b| b.distance(a) > 1e-6)
            .min_by(|x, y| seg_dist(*x).total_cmp(&seg_dist(*y)))
            .unwrap_or_else(|| {
                let e = (centroid - a).normalize_or_zero();
                let far = verts.iter().map(|p| (*p - a).dot(e)).fold(0.0f32, f32::max);
                a + e * far
            });
        let mut c = BoneCapsule {
            joint: j,
            a,
            b,
            r: 0.0,
        };
        let mut d: Vec<f32> = verts.iter().map(|p| c.axis_distance(*p)).collect();
        d.sort_by(f32::total_cmp);
        c.r = d[((d.len() - 1) as f32 * RADIUS_PERCENTILE) as usize];
        if c.r > 1e-5 {
            out.push(c);
        }
    }
    out
}
