//! Colliders the fluid stays outside of (spheres, capsules, planes; static or moving)
//! and their GPU mirror.
use crate::error::{Error, Result};
use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

/// Mirror of `Collider` in glsl/sph/common.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuCollider {
    pub a: [f32; 4],
    pub b: [f32; 4],
    pub vel: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuCollider>() == 48);

/// Static or moving colliders; the fluid stays outside spheres and capsules and on the
/// positive side of planes. Moving colliders carry their velocity for the response.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Collider {
    Plane {
        normal: [f32; 3],
        offset: f32,
        #[serde(default)]
        velocity: [f32; 3],
    },
    Sphere {
        center: [f32; 3],
        radius: f32,
        #[serde(default)]
        velocity: [f32; 3],
    },
    Capsule {
        a: [f32; 3],
        b: [f32; 3],
        radius: f32,
        #[serde(default)]
        velocity: [f32; 3],
    },
}

/// Most colliders a scene may have.
pub const MAX_COLLIDERS: usize = 64;

impl Collider {
    pub fn to_gpu(&self) -> Result<GpuCollider> {
        let v = |v: &[f32; 3]| [v[0], v[1], v[2], 0.0];
        Ok(match self {
            Collider::Plane {
                normal,
                offset,
                velocity,
            } => {
                let n = glam::Vec3::from(*normal);
                if n.length().is_nan() || n.length() <= 1e-6 {
                    return Err(Error::Param(
                        "plane collider: normal must be non-zero".into(),
                    ));
                }
                let n = n.normalize();
                GpuCollider {
                    a: [n.x, n.y, n.z, *offset],
                    b: [0.0, 0.0, 0.0, 0.0],
                    vel: v(velocity),
                }
            }
            Collider::Sphere {
                center,
                radius,
                velocity,
            } => {
                if radius.is_nan() || *radius <= 0.0 {
                    return Err(Error::Param(
                        "sphere collider: radius must be positive".into(),
                    ));
                }
                GpuCollider {
                    a: [center[0], center[1], center[2], *radius],
                    b: [0.0, 0.0, 0.0, 1.0],
                    vel: v(velocity),
                }
            }
            Collider::Capsule {
                a,
                b,
                radius,
                velocity,
            } => {
                if radius.is_nan() || *radius <= 0.0 {
                    return Err(Error::Param(
                        "capsule collider: radius must be positive".into(),
                    ));
                }
                GpuCollider {
                    a: [a[0], a[1], a[2], *radius],
                    b: [b[0], b[1], b[2], 2.0],
                    vel: v(velocity),
                }
            }
        })
    }

    pub fn scaled(&self, s: f32) -> Self {
        let m = |v: &[f32; 3]| [v[0] * s, v[1] * s, v[2] * s];
        match self {
            Collider::Plane {
                normal,
                offset,
                velocity,
            } => Collider::Plane {
                normal: *normal,
                offset: offset * s,
                velocity: *velocity,
            },
            Collider::Sphere {
                center,
                radius,
                velocity,
            } => Collider::Sphere {
                center: m(center),
                radius: radius * s,
                velocity: *velocity,
            },
            Collider::Capsule {
                a,
                b,
                radius,
                velocity,
            } => Collider::Capsule {
                a: m(a),
                b: m(b),
                radius: radius * s,
                velocity: *velocity,
            },
        }
    }

    /// Signed distance to the collider surface (negative inside the solid).
    pub fn distance(&self, p: [f32; 3]) -> f32 {
        let p = glam::Vec3::from(p);
        match self {
            Collider::Plane { normal, offset, .. } => {
                glam::Vec3::from(*normal).normalize().dot(p) - offset
            }
            Collider::Sphere { center, radius, .. } => {
                (p - glam::Vec3::from(*center)).length() - radius
            }
            Collider::Capsule { a, b, radius, .. } => {
                let (a, b) = (glam::Vec3::from(*a), glam::Vec3::from(*b));
                let ab = b - a;
                let t = ((p - a).dot(ab) / ab.length_squared().max(1e-20)).clamp(0.0, 1.0);
                (p - (a + t * ab)).length() - radius
            }
        }
    }
}
