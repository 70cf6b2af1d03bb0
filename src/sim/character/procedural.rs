//! Built-in shapes needing no files: `walker`, a skinned character (13 joints, a looping
//! one-second walk), and `giraffe`, a static long-necked shape whose neck is 2.5 rest
//! spacings of the default fluid thick (the adaptive-pressure test). Both are smooth unions
//! of capsules polygonised by marching tetrahedra, so they are closed and manifold.
use super::model::*;
use crate::error::{Error, Result};
use glam::{Mat4, Quat, Vec3, Vec4};
use std::collections::HashMap;

pub const BUILT_IN: &[&str] = &["walker", "giraffe", "capsule"];

/// Grid steps of the polygonisation (metres): the giraffe's finer, for its thin neck.
const WALKER_STEP: f32 = 0.018;
const GIRAFFE_STEP: f32 = 0.0125;

pub fn built_in(name: &str) -> Result<Character> {
    match name {
        "walker" => walker(),
        "giraffe" => giraffe(),
        "capsule" => capsule(),
        _ => Err(Error::Param(format!(
            "unknown built-in shape '{name}' (builtin:{})",
            BUILT_IN.join(", builtin:")
        ))),
    }
}

#[derive(Clone, Copy)]
struct Capsule {
    a: Vec3,
    b: Vec3,
    r: f32,
}

impl Capsule {
    fn dist(&self, p: Vec3) -> f32 {
        let ab = self.b - self.a;
        let s = ((p - self.a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
        (p - (self.a + ab * s)).length()
    }
}

fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

fn field(caps: &[Capsule], p: Vec3) -> f32 {
    caps.iter()
        .map(|c| c.dist(p) - c.r)
        .fold(f32::INFINITY, |acc, d| smin(acc, d, 0.03))
}

/// Marching tetrahedra over the zero set of `f` (negative inside) on a grid of `step`:
/// six tetrahedra per cube around its main diagonal, so neighbouring cubes split shared
/// faces alike and the surface is watertight; edge vertices are shared by key.
pub fn polygonise(f: &dyn Fn(Vec3) -> f32, lo: Vec3, hi: Vec3, step: f32) -> (Vec<Vec3>, Vec<u32>) {
    let lo = lo - Vec3::splat(2.0 * step);
    let dims = ((hi - lo) / step).ceil().as_uvec3() + glam::UVec3::splat(3);
    let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
    let at = |i: usize, j: usize, k: usize| lo + Vec3::new(i as f32, j as f32, k as f32) * step;
    // Values never exactly zero (or so near it that two edge vertices would weld).
    let mut val = vec![0f32; nx * ny * nz];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v = f(at(i, j, k));
                val[i + nx * (j + ny * k)] = if v.abs() < 1e-3 * step {
                    1e-3 * step
                } else {
                    v
                };
            }
        }
    }
    const TETS: [[usize; 4]; 6] = [
        [0, 1, 3, 7],
        [0, 3, 2, 7],
        [0, 2, 6, 7],
        [0, 6, 4, 7],
        [0, 4, 5, 7],
        [0, 5, 1, 7],
    ];
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    let mut edges: HashMap<(usize, usize), u32> = HashMap::new();
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let g =
                    |c: usize| (i + (c & 1)) + nx * ((j + ((c >> 1) & 1)) + ny * (k + (c >> 2)));
                let corner = |c: usize| at(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
                for t in TETS {
                    let ids = t.map(g);
                    let inside: Vec<usize> = (0..4).filter(|&q| val[ids[q]] < 0.0).collect();
                    if inside.is_empty() || inside.len() == 4 {
                        continue;
                    }
                    let outside: Vec<usize> = (0..4).filter(|&q| val[ids[q]] >= 0.0).collect();
                    let mut vert = |a: usize, b: usize| -> u32 {
                        let key = (ids[a].min(ids[b]), ids[a].max(ids[b]));
                        *edges.entry(key).or_insert_with(|| {
                            let (fa, fb) = (val[ids[a]], val[ids[b]]);
                            let s = fa / (fa - fb);
                            pos.push(corner(t[a]).lerp(corner(t[b]), s));
                            (pos.len() - 1) as u32
                        })
                    };
                    let mut tris: Vec<[u32; 3]> = Vec::new();
                    match (inside.len(), outside.len()) {
                        (1, 3) => {
                            let a = inside[0];
                            tris.push([
                                vert(a, outside[0]),
                                vert(a, outside[1]),
                                vert(a, outside[2]),
                            ]);
                        }
                        (3, 1) => {
                            let a = outside[0];
                            tris.push([vert(a, inside[0]), vert(a, inside[1]), vert(a, inside[2])]);
                        }
                        _ => {
                            let (a, b, c, d) = (inside[0], inside[1], outside[0], outside[1]);
                            let q = [vert(a, c), vert(a, d), vert(b, d), vert(b, c)];
                            tris.push([q[0], q[1], q[2]]);
                            tris.push([q[0], q[2], q[3]]);
                        }
                    }
                    // Wind each triangle so its normal points from inside to outside.
                    let cen = |s: &[usize]| {
                        s.iter().map(|&q| corner(t[q])).sum::<Vec3>() / s.len() as f32
                    };
                    let out_dir = cen(&outside) - cen(&inside);
                    for tri in tris {
                        let [a, b, c] = tri.map(|v| pos[v as usize]);
                        let flip = (b - a).cross(c - a).dot(out_dir) < 0.0;
                        idx.extend(if flip { [tri[0], tri[2], tri[1]] } else { tri });
                    }
                }
            }
        }
    }
    (pos, idx)
}

fn shape_bounds(caps: &[Capsule]) -> (Vec3, Vec3) {
    caps.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), c| (lo.min(c.a.min(c.b) - c.r), hi.max(c.a.max(c.b) + c.r)),
    )
}

/// A bone: name, parent, joint position (its head) and the capsule it carries.
struct Bone {
    name: String,
    parent: Option<usize>,
    head: Vec3,
    cap: Capsule,
}

fn bone(name: &str, parent: Option<usize>, a: [f32; 3], b: [f32; 3], r: f32) -> Bone {
    let (a, b) = (Vec3::from(a), Vec3::from(b));
    Bone {
        name: name.to_string(),
        parent,
        head: a,
        cap: Capsule { a, b, r },
    }
}

/// Each bone's capsule, carried by its joint (joints are the bones, in order).
fn bone_capsules(bones: &[Bone]) -> Vec<super::capsules::BoneCapsule> {
    bones
        .iter()
        .enumerate()
        .map(|(joint, b)| super::capsules::BoneCapsule {
            joint,
            a: b.cap.a,
            b: b.cap.b,
            r: b.cap.r,
        })
        .collect()
}

/// A rigid shape's capsules, all on its one joint.
fn rigid_capsules(caps: &[Capsule]) -> Vec<super::capsules::BoneCapsule> {
    caps.iter()
        .map(|c| super::capsules::BoneCapsule {
            joint: 0,
            a: c.a,
            b: c.b,
            r: c.r,
        })
        .collect()
}

/// The walker's skeleton (about 1.05 m tall, Y up, facing +Z).
fn walker_bones() -> Vec<Bone> {
    let mut b = vec![
        bone("hips", None, [0.0, 0.52, 0.0], [0.0, 0.60, 0.0], 0.085),
        bone("spine", Some(0), [0.0, 0.60, 0.0], [0.0, 0.74, 0.0], 0.085),
        bone("chest", Some(1), [0.0, 0.74, 0.0], [0.0, 0.82, 0.0], 0.095),
        bone("neck", Some(2), [0.0, 0.86, 0.0], [0.0, 0.90, 0.0], 0.035),
        bone("head", Some(3), [0.0, 0.90, 0.0], [0.0, 0.99, 0.01], 0.065),
    ];
    for (side, s) in [("l", 1.0f32), ("r", -1.0)] {
        let leak = |n: &str| format!("{n}_{side}");
        let ua = b.len();
        b.push(bone(
            &leak("upper_arm"),
            Some(2),
            [0.10 * s, 0.84, 0.0],
            [0.18 * s, 0.65, 0.0],
            0.034,
        ));
        b.push(bone(
            &leak("forearm"),
            Some(ua),
            [0.18 * s, 0.65, 0.0],
            [0.20 * s, 0.48, 0.02],
            0.028,
        ));
        let th = b.len();
        b.push(bone(
            &leak("thigh"),
            Some(0),
            [0.065 * s, 0.50, 0.0],
            [0.07 * s, 0.27, 0.0],
            0.048,
        ));
        b.push(bone(
            &leak("shin"),
            Some(th),
            [0.07 * s, 0.27, 0.0],
            [0.07 * s, 0.045, 0.0],
            0.038,
        ));
    }
    b
}

/// Rest translations of every bone node relative to its parent (rest rotations identity).
fn skeleton_of(bones: &[Bone]) -> Skeleton {
    let nodes: Vec<Node> = bones
        .iter()
        .map(|b| Node {
            name: b.name.clone(),
            parent: b.parent,
            rest: Trs {
                t: b.head - b.parent.map(|p| bones[p].head).unwrap_or(Vec3::ZERO),
                ..Default::default()
            },
        })
        .collect();
    let joints = bones
        .iter()
        .enumerate()
        .map(|(i, b)| Joint {
            node: i,
            inverse_bind: Mat4::from_translation(-b.head),
        })
        .collect();
    let order = Skeleton::sort(&nodes).expect("a tree");
    Skeleton {
        nodes,
        joints,
        order,
    }
}

fn walk_clip(bones: &[Bone]) -> Clip {
    let find = |n: &str| bones.iter().position(|b| b.name == n).unwrap();
    let times: Vec<f32> = (0..=8).map(|k| k as f32 / 8.0).collect();
    let phase = |t: f32| (t * std::f32::consts::TAU).sin();
    let rot = |node: usize, f: &dyn Fn(f32) -> Quat| Channel {
        node,
        property: Property::Rotation,
        interp: Interp::Linear,
        times: times.clone(),
        values: times.iter().map(|&t| Vec4::from(f(t))).collect(),
    };
    let deg = |d: f32| d.to_radians();
    let mut channels = Vec::new();
    for (side, s) in [("l", 1.0f32), ("r", -1.0)] {
        let (th, sh) = (
            find(&format!("thigh_{side}")),
            find(&format!("shin_{side}")),
        );
        let (ua, fa) = (
            find(&format!("upper_arm_{side}")),
            find(&format!("forearm_{side}")),
        );
        channels.push(rot(th, &move |t| {
            Quat::from_rotation_x(deg(-28.0) * s * phase(t))
        }));
        // The knee bends on the back swing only.
        channels.push(rot(sh, &move |t| {
            Quat::from_rotation_x(deg(35.0) * (0.5 - 0.5 * (s * phase(t + 0.1))).powi(2))
        }));
        channels.push(rot(ua, &move |t| {
            Quat::from_rotation_x(deg(24.0) * s * phase(t))
        }));
        channels.push(rot(fa, &move |_| Quat::from_rotation_x(deg(-15.0))));
    }
    channels.push(rot(find("spine"), &|t| {
        Quat::from_rotation_y(deg(6.0) * phase(t))
    }));
    channels.push(rot(find("head"), &|t| {
        Quat::from_rotation_y(deg(-6.0) * phase(t))
    }));
    // The hips bob twice per cycle.
    let hips = find("hips");
    channels.push(Channel {
        node: hips,
        property: Property::Translation,
        interp: Interp::Linear,
        times: times.clone(),
        values: times
            .iter()
            .map(|&t| {
                (bones[hips].head + Vec3::Y * 0.015 * (2.0 * t * std::f32::consts::TAU).cos())
                    .extend(0.0)
            })
            .collect(),
    });
    Clip {
        name: "walk".into(),
        duration: 1.0,
        channels,
    }
}

/// Each vertex bound to its two nearest bones, weights by inverse squared distance.
fn bind(mesh: &mut Mesh, bones: &[Bone]) {
    for p in &mesh.positions {
        let mut d: Vec<(usize, f32)> = bones
            .iter()
            .enumerate()
            .map(|(i, b)| (i, b.cap.dist(*p)))
            .collect();
        d.sort_by(|a, b| a.1.total_cmp(&b.1));
        let w = [d[0], d[1]].map(|(_, x)| 1.0 / (x * x + 1e-6));
        let sum = w[0] + w[1];
        let mut joints = [0u16; MAX_INFLUENCES];
        let mut weights = [0f32; MAX_INFLUENCES];
        for k in 0..2 {
            joints[k] = d[k].0 as u16;
            weights[k] = w[k] / sum;
        }
        mesh.joints.push(joints);
        mesh.weights.push(weights);
    }
}

fn shape(caps: &[Capsule], step: f32) -> (Mesh, Vec<bool>) {
    let (lo, hi) = shape_bounds(caps);
    let (positions, indices) = polygonise(&|p| field(caps, p), lo, hi, step);
    let n = positions.len();
    (
        Mesh {
            normals: vec![Vec3::ZERO; n],
            positions,
            indices,
            influence_sets: 1,
            ..Default::default()
        },
        vec![false; n],
    )
}

fn walker() -> Result<Character> {
    let bones = walker_bones();
    let caps: Vec<Capsule> = bones.iter().map(|b| b.cap).collect();
    let (mut mesh, has) = shape(&caps, WALKER_STEP);
    bind(&mut mesh, &bones);
    let skel = skeleton_of(&bones);
    let clip = walk_clip(&bones);
    let mut ch = super::assemble(
        "builtin:walker".into(),
        (mesh, has),
        skel,
        vec![clip],
        true,
        Vec::new(),
    )?;
    ch.capsules = bone_capsules(&bones);
    Ok(ch)
}

/// Neck radius: 1.25 rest spacings of the default fluid (2.5 spacings thick).
pub fn giraffe_neck_radius() -> f32 {
    1.25 * crate::sph::FluidParams::default().spacing()
}

fn giraffe() -> Result<Character> {
    let r = giraffe_neck_radius();
    let c = |a: [f32; 3], b: [f32; 3], r: f32| Capsule {
        a: a.into(),
        b: b.into(),
        r,
    };
    let mut caps = vec![
        c([-0.15, 0.45, 0.0], [0.13, 0.47, 0.0], 0.11),
        c([0.15, 0.52, 0.0], [0.30, 0.95, 0.0], r),
        c([0.28, 0.99, 0.0], [0.40, 0.95, 0.0], 0.045),
    ];
    for (x, z) in [(-0.13, 0.06), (-0.13, -0.06), (0.11, 0.06), (0.11, -0.06)] {
        caps.push(c([x, 0.40, z], [x, 0.03, z], 0.032));
    }
    let (mut mesh, has) = shape(&caps, GIRAFFE_STEP);
    let n = mesh.vertices();
    mesh.joints = vec![[0; MAX_INFLUENCES]; n];
    mesh.weights = vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]; n];
    let mut ch = super::assemble(
        "builtin:giraffe".into(),
        (mesh, has),
        Skeleton::single("giraffe"),
        Vec::new(),
        false,
        Vec::new(),
    )?;
    ch.capsules = rigid_capsules(&caps);
    Ok(ch)
}

/// A vertical capsule (radius 0.08 m, 0.36 m tall): the simplest closed control target.
fn capsule() -> Result<Character> {
    let caps = [Capsule {
        a: Vec3::new(0.0, 0.08, 0.0),
        b: Vec3::new(0.0, 0.28, 0.0),
        r: 0.08,
    }];
    let (mut mesh, has) = shape(&caps, WALKER_STEP);
    let n = mesh.vertices();
    mesh.joints = vec![[0; MAX_INFLUENCES]; n];
    mesh.weights = vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]; n];
    let mut ch = super::assemble(
        "builtin:capsule".into(),
        (mesh, has),
        Skeleton::single("capsule"),
        Vec::new(),
        false,
        Vec::new(),
    )?;
    ch.capsules = rigid_capsules(&caps);
    Ok(ch)
}
