//! Binding control particles to the skeleton in the rest pose (seed 000, 3.2.4): each to
//! its two nearest bones (distance to the bone segment), weights by eq. 8
//! (w_1 = d_2 / (d_1 + d_2)) or eq. 9 as reconstructed (normalised inverse squared
//! distance; the thesis's eq. 9 is lost), or `skin`: the skin weights of the nearest
//! surface vertex (ours, a comparison the thesis did not have).
use crate::character::{Character, MAX_INFLUENCES};
use crate::control::BoneWeights;
use glam::{Mat4, Vec3};

/// A joint's bones in the rest pose: segments from it to each child joint (a point for a
/// leaf).
#[derive(Clone, Debug)]
pub struct Bone {
    pub joint: usize,
    pub segments: Vec<(Vec3, Vec3)>,
}

impl Bone {
    pub fn distance(&self, p: Vec3) -> f32 {
        self.segments
            .iter()
            .map(|&(a, b)| {
                let ab = b - a;
                let s = if ab.length_squared() > 0.0 {
                    ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                p.distance(a + ab * s)
            })
            .fold(f32::INFINITY, f32::min)
    }
}

/// Bones of `ch` with node globals `globals` (the rest pose, placement applied).
pub fn bones(ch: &Character, globals: &[Mat4]) -> Vec<Bone> {
    let sk = &ch.skeleton;
    let head = |j: usize| globals[sk.joints[j].node].w_axis.truncate();
    (0..sk.joints.len())
        .map(|j| {
            let node = sk.joints[j].node;
            let mut segments: Vec<(Vec3, Vec3)> = (0..sk.joints.len())
                .filter(|&k| sk.nodes[sk.joints[k].node].parent == Some(node))
                .map(|k| (head(j), head(k)))
                .collect();
            if segments.is_empty() {
                segments.push((head(j), head(j)));
            }
            Bone { joint: j, segments }
        })
        .collect()
}

/// Two weights from the distances to the two nearest bones.
pub fn pair_weights(how: BoneWeights, d1: f32, d2: f32) -> [f32; 2] {
    match how {
        BoneWeights::Eq8 => match d1 + d2 {
            s if s > 0.0 => [d2 / s, d1 / s],
            _ => [1.0, 0.0],
        },
        _ => {
            if d1 <= 0.0 {
                return [1.0, 0.0];
            }
            let (a, b) = (1.0 / (d1 * d1), 1.0 / (d2 * d2));
            [a / (a + b), b / (a + b)]
        }
    }
}

/// Joint indices and weights (heaviest first) of every point. `rest_vertices` are the
/// mesh's rest positions (for `skin`).
pub fn bind(
    ch: &Character,
    bones: &[Bone],
    points: &[Vec3],
    how: BoneWeights,
    rest_vertices: &[Vec3],
) -> (Vec<[u16; MAX_INFLUENCES]>, Vec<[f32; MAX_INFLUENCES]>) {
    let mut joints = Vec::with_capacity(points.len());
    let mut weights = Vec::with_capacity(points.len());
    for p in points {
        let (mut j, mut w) = ([0u16; MAX_INFLUENCES], [0f32; MAX_INFLUENCES]);
        if how == BoneWeights::Skin {
            let v = nearest(rest_vertices, *p);
            j = ch.mesh.joints[v];
            w = ch.mesh.weights[v];
        } else if bones.len() == 1 {
            j[0] = bones[0].joint as u16;
            w[0] = 1.0;
        } else {
            let mut d: Vec<(usize, f32)> =
                bones.iter().map(|b| (b.joint, b.distance(*p))).collect();
            d.sort_by(|a, b| a.1.total_cmp(&b.1));
            let pw = pair_weights(how, d[0].1, d[1].1);
            j[0] = d[0].0 as u16;
            j[1] = d[1].0 as u16;
            w[0] = pw[0];
            w[1] = pw[1];
        }
        joints.push(j);
        weights.push(w);
    }
    (joints, weights)
}

fn nearest(vertices: &[Vec3], p: Vec3) -> usize {
    let mut best = (0, f32::INFINITY);
    for (i, v) in vertices.iter().enumerate() {
        let d = v.distance_squared(p);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}
