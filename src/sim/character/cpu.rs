//! CPU reference of the skinning pass, in the same f32 operations as
//! glsl/character/skin.comp, for the tests.
use super::pose::GpuJoint;
use crate::character::Skinning;
use glam::{Mat3, Vec3, Vec4};

fn cofactor(a: Mat3) -> Mat3 {
    Mat3::from_cols(
        a.y_axis.cross(a.z_axis),
        a.z_axis.cross(a.x_axis),
        a.x_axis.cross(a.y_axis),
    )
}

fn rotate(q: Vec4, v: Vec3) -> Vec3 {
    let u = q.truncate();
    v + 2.0 * u.cross(u.cross(v) + q.w * v)
}

/// Skinned position and normal of one vertex.
pub fn skin_vertex(
    method: Skinning,
    joints: &[GpuJoint],
    p: Vec3,
    n: Vec3,
    ids: &[u16],
    w: &[f32],
) -> (Vec3, Vec3) {
    let m3 = |j: &GpuJoint| {
        Mat3::from_cols(
            Vec4::from(j.m[0]).truncate(),
            Vec4::from(j.m[1]).truncate(),
            Vec4::from(j.m[2]).truncate(),
        )
    };
    match method {
        Skinning::Lbs => {
            let mut a = Mat3::ZERO;
            let mut t = Vec3::ZERO;
            for (&id, &wi) in ids.iter().zip(w) {
                let j = &joints[id as usize];
                a += m3(j) * wi;
                t += Vec4::from(j.m[3]).truncate() * wi;
            }
            (a * p + t, (cofactor(a) * n).normalize_or_zero())
        }
        Skinning::Dqs => {
            let q0 = Vec4::from(joints[ids[0] as usize].real);
            let (mut r, mut d, mut s) = (Vec4::ZERO, Vec4::ZERO, Mat3::ZERO);
            for (&id, &wi) in ids.iter().zip(w) {
                let j = &joints[id as usize];
                let real = Vec4::from(j.real);
                // Antipodality: blend every rotation on the hemisphere of the heaviest.
                let sw = if real.dot(q0) < 0.0 { -wi } else { wi };
                r += real * sw;
                d += Vec4::from(j.dual) * sw;
                s += Mat3::from_cols(
                    Vec4::from(j.s[0]).truncate(),
                    Vec4::from(j.s[1]).truncate(),
                    Vec4::from(j.s[2]).truncate(),
                ) * wi;
            }
            let len = r.length();
            let (r, d) = (r / len, d / len);
            let t =
                2.0 * (r.w * d.truncate() - d.w * r.truncate() + r.truncate().cross(d.truncate()));
            let ps = rotate(r, s * p) + t;
            (ps, rotate(r, cofactor(s) * n).normalize_or_zero())
        }
    }
}

/// Skin every vertex of `mesh` with `joints`, its morph targets first at `weights`.
pub fn skin(
    method: Skinning,
    joints: &[GpuJoint],
    mesh: &super::Mesh,
    weights: &[f32],
) -> (Vec<Vec3>, Vec<Vec3>) {
    let k = 4 * mesh.influence_sets;
    (0..mesh.vertices())
        .map(|v| {
            let (p, n) = mesh
                .morphs
                .apply(v, mesh.positions[v], mesh.normals[v], weights);
            skin_vertex(
                method,
                joints,
                p,
                n,
                &mesh.joints[v][..k],
                &mesh.weights[v][..k],
            )
        })
        .unzip()
}
