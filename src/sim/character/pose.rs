//! Joint matrices -> what the skinning shader reads: the matrix for linear blending, and
//! for dual quaternions the polar split M = [R S | t] (Kavan et al. 2008, §4: the
//! scale/shear S blended linearly first, the rigid part R, t as a unit dual quaternion).
use crate::character::Skinning;
use crate::error::{Error, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};

/// glsl/character/skin.comp `Joint`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuJoint {
    /// Column-major joint matrix.
    pub m: [[f32; 4]; 4],
    /// Rotation quaternion (xyzw) of the rigid part.
    pub real: [f32; 4],
    /// Dual part: 0.5 * (t, 0) * real.
    pub dual: [f32; 4],
    /// Columns of the symmetric stretch S (w unused).
    pub s: [[f32; 4]; 3],
}
const _: () = assert!(std::mem::size_of::<GpuJoint>() == 144);

/// A = R S with R a rotation and S symmetric (A with positive determinant), by Higham's
/// scaled Newton iteration in f64 (a few steps at any scale); None when it does not reach
/// an orthonormal R.
pub fn polar(a: Mat3) -> Option<(Mat3, Mat3)> {
    let norm = |m: glam::DMat3| m.to_cols_array().iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut r = a.as_dmat3();
    for _ in 0..64 {
        let inv_t = r.inverse().transpose();
        let g = (norm(inv_t) / norm(r)).sqrt();
        let next = (r * g + inv_t * (1.0 / g)) * 0.5;
        let diff = norm(next - r);
        r = next;
        if diff < 1e-12 {
            break;
        }
    }
    let ortho = norm(r.transpose() * r - glam::DMat3::IDENTITY);
    if ortho.is_nan() || ortho >= 1e-6 {
        return None;
    }
    let s = r.transpose() * a.as_dmat3();
    Some((r.as_mat3(), ((s + s.transpose()) * 0.5).as_mat3()))
}

/// The dual quaternion (real, dual) of rotation `q` then translation `t`.
pub fn dual_quat(q: Quat, t: Vec3) -> (Vec4, Vec4) {
    let d = Quat::from_xyzw(t.x, t.y, t.z, 0.0) * q * 0.5;
    (Vec4::from(q), Vec4::from(d))
}

/// Shader joints for `mats`; dual quaternions refuse mirroring joints (negative determinant).
pub fn gpu_joints(
    mats: &[Mat4],
    method: Skinning,
    names: &dyn Fn(usize) -> String,
) -> Result<Vec<GpuJoint>> {
    mats.iter()
        .enumerate()
        .map(|(i, m)| {
            let a = Mat3::from_mat4(*m);
            let det = a.determinant();
            let size = a.to_cols_array().iter().map(|x| x * x).sum::<f32>().sqrt();
            let t = m.w_axis.truncate();
            let split = (det > 0.0 && det.is_finite()).then(|| polar(a)).flatten();
            let (real, dual, s) = if let Some((r, s)) = split {
                let (real, dual) = dual_quat(Quat::from_mat3(&r).normalize(), t);
                (real, dual, s)
            } else if size.is_finite() && det.abs() <= 1e-9 * size * size * size {
                // Collapsed (a part scaled to nothing to hide it): no rotation, the whole
                // linear part as the stretch, so R S p + t is still A p + t.
                let (real, dual) = dual_quat(Quat::IDENTITY, t);
                (real, dual, a)
            } else if method == Skinning::Dqs {
                return Err(Error::Unsupported(format!(
                    "joint {i} ({}) has a matrix with determinant {det} (a mirror): \
                     dual quaternions cannot represent it; use --skinning lbs",
                    names(i)
                )));
            } else {
                (Vec4::W, Vec4::ZERO, Mat3::IDENTITY)
            };
            let col = |v: Vec3| [v.x, v.y, v.z, 0.0];
            Ok(GpuJoint {
                m: m.to_cols_array_2d(),
                real: real.into(),
                dual: dual.into(),
                s: [col(s.x_axis), col(s.y_axis), col(s.z_axis)],
            })
        })
        .collect()
}
