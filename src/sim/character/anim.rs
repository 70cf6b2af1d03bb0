//! Clip sampling (glTF 2.0 §3.11 and Appendix C): STEP, LINEAR (rotations by shortest-path
//! slerp) and CUBICSPLINE (Hermite with tangents scaled by the key interval), looping or
//! clamped; then node globals and joint matrices.
use super::model::{Channel, Clip, Interp, Property, Skeleton, Trs};
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};

/// Where `t` falls in a clip of length `duration`.
pub fn clip_time(t: f32, duration: f32, looping: bool) -> f32 {
    if duration <= 0.0 {
        return 0.0;
    }
    if looping {
        t.rem_euclid(duration)
    } else {
        t.clamp(0.0, duration)
    }
}

/// Shortest-path spherical interpolation of unit quaternions (xyzw in Vec4).
pub fn slerp(a: Vec4, b: Vec4, s: f32) -> Vec4 {
    let mut b = b;
    let mut d = a.dot(b);
    if d < 0.0 {
        b = -b;
        d = -d;
    }
    if d > 0.9995 {
        return a.lerp(b, s).normalize();
    }
    let theta = d.clamp(-1.0, 1.0).acos();
    let sin = theta.sin();
    (a * ((1.0 - s) * theta).sin() + b * (s * theta).sin()) / sin
}

impl Channel {
    /// The channel's value at clip time `t` (rotations normalised).
    pub fn sample(&self, t: f32) -> Vec4 {
        let n = self.times.len();
        let key = |k: usize| match self.interp {
            Interp::CubicSpline => self.values[3 * k + 1],
            _ => self.values[k],
        };
        let v = if n == 1 || t <= self.times[0] {
            key(0)
        } else if t >= self.times[n - 1] {
            key(n - 1)
        } else {
            // The last key with time <= t.
            let k = self.times.partition_point(|&x| x <= t) - 1;
            let (t0, t1) = (self.times[k], self.times[k + 1]);
            let dt = t1 - t0;
            let s = if dt > 0.0 { (t - t0) / dt } else { 0.0 };
            match self.interp {
                Interp::Step => key(k),
                Interp::Linear if self.property == Property::Rotation => {
                    slerp(key(k), key(k + 1), s)
                }
                Interp::Linear => key(k).lerp(key(k + 1), s),
                Interp::CubicSpline => {
                    let (v0, b0) = (self.values[3 * k + 1], self.values[3 * k + 2]);
                    let (a1, v1) = (self.values[3 * (k + 1)], self.values[3 * (k + 1) + 1]);
                    let (s2, s3) = (s * s, s * s * s);
                    v0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                        + b0 * (dt * (s3 - 2.0 * s2 + s))
                        + v1 * (-2.0 * s3 + 3.0 * s2)
                        + a1 * (dt * (s3 - s2))
                }
            }
        };
        match self.property {
            Property::Rotation => v.normalize(),
            _ => v,
        }
    }
}

impl Clip {
    /// Local transforms of every node at time `t`: rest values where no channel drives one.
    pub fn locals(&self, skel: &Skeleton, t: f32, looping: bool) -> Vec<Trs> {
        let t = clip_time(t, self.duration, looping);
        let mut locals = skel.rest_locals();
        for c in &self.channels {
            let v = c.sample(t);
            let l = &mut locals[c.node];
            match c.property {
                Property::Translation => l.t = v.truncate(),
                Property::Rotation => l.r = Quat::from_vec4(v),
                Property::Scale => l.s = v.truncate(),
                Property::Weight(_) => {}
            }
        }
        locals
    }

    /// Every morph target's weight at time `t`: its channel's, else its default.
    pub fn morph_weights(&self, morphs: &super::Morphs, t: f32, looping: bool) -> Vec<f32> {
        let t = clip_time(t, self.duration, looping);
        let mut w = morphs.defaults();
        for c in &self.channels {
            let Property::Weight(k) = c.property else {
                continue;
            };
            let slot =
                (morphs.targets.iter()).position(|m| m.node == c.node && m.index == k as usize);
            if let Some(slot) = slot {
                w[slot] = c.sample(t).x;
            }
        }
        w
    }
}

/// What drives the pose: a clip (or the rest pose), looping or clamped, and the placement.
#[derive(Clone, Debug)]
pub struct Animator {
    pub clip: Option<usize>,
    pub looping: bool,
    /// Placement in the scene, applied after the skin (scale, rotation, position).
    pub placement: Mat4,
}

impl Animator {
    /// Morph target weights at time `t` (the defaults without a clip).
    pub fn morph_weights(&self, ch: &super::Character, t: f32) -> Vec<f32> {
        match self.clip {
            Some(c) => ch.clips[c].morph_weights(&ch.mesh.morphs, t, self.looping),
            None => ch.mesh.morphs.defaults(),
        }
    }

    /// Joint matrices at time `t`, with the placement applied.
    pub fn joint_matrices(&self, ch: &super::Character, t: f32) -> Vec<Mat4> {
        let locals = match self.clip {
            Some(c) => ch.clips[c].locals(&ch.skeleton, t, self.looping),
            None => ch.skeleton.rest_locals(),
        };
        let g = ch.skeleton.globals(&locals);
        ch.skeleton
            .joint_matrices(&g)
            .into_iter()
            .map(|m| self.placement * m)
            .collect()
    }
}

/// A file's up axis (OBJ has no convention; many are Z-up), turned to +Y before the
/// scene's `rotation`: Z-up by -90 degrees about X (so +Y, the file's depth, faces back).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Up {
    #[default]
    #[serde(rename = "y")]
    Y,
    #[serde(rename = "-y")]
    NegY,
    #[serde(rename = "z")]
    Z,
    #[serde(rename = "-z")]
    NegZ,
    #[serde(rename = "x")]
    X,
    #[serde(rename = "-x")]
    NegX,
}

impl Up {
    pub const ALL: [Up; 6] = [Up::Y, Up::NegY, Up::Z, Up::NegZ, Up::X, Up::NegX];

    pub fn name(self) -> &'static str {
        match self {
            Up::Y => "y",
            Up::NegY => "-y",
            Up::Z => "z",
            Up::NegZ => "-z",
            Up::X => "x",
            Up::NegX => "-x",
        }
    }

    /// The rotation taking this axis to +Y.
    pub fn matrix(self) -> Mat3 {
        use std::f32::consts::{FRAC_PI_2, PI};
        match self {
            Up::Y => Mat3::IDENTITY,
            Up::NegY => Mat3::from_rotation_z(PI),
            Up::Z => Mat3::from_rotation_x(-FRAC_PI_2),
            Up::NegZ => Mat3::from_rotation_x(FRAC_PI_2),
            Up::X => Mat3::from_rotation_z(FRAC_PI_2),
            Up::NegX => Mat3::from_rotation_z(-FRAC_PI_2),
        }
    }
}

impl std::str::FromStr for Up {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Up::ALL.into_iter().find(|u| u.name() == s).ok_or_else(|| {
            let all: Vec<&str> = Up::ALL.iter().map(|u| u.name()).collect();
            format!("up axis '{s}' is not one of {}", all.join(", "))
        })
    }
}

/// The placement's orientation: the up axis to +Y, then `rotation` (XYZ Euler degrees).
pub fn orientation(up: Up, rotation_deg: Vec3) -> Mat3 {
    let r = Quat::from_euler(
        glam::EulerRot::XYZ,
        rotation_deg.x.to_radians(),
        rotation_deg.y.to_radians(),
        rotation_deg.z.to_radians(),
    );
    Mat3::from_quat(r) * up.matrix()
}

/// The bounds of `rest` (file coordinates) turned by `orient`.
pub fn turned_bounds(rest: &[Vec3], orient: Mat3) -> (Vec3, Vec3) {
    let turned: Vec<Vec3> = rest.iter().map(|p| orient * *p).collect();
    super::check::bounds(&turned)
}

/// The placement that stands a rest pose turned by `orient`, whose turned bounds are
/// `(lo, hi)`, with the bottom centre of those bounds at `position`, scaled by `scale`
/// about that point: one pivot, so the fitted domain, the pool and the control particles
/// all see the character where it stands.
pub fn stand((lo, hi): (Vec3, Vec3), orient: Mat3, scale: f32, position: Vec3) -> Mat4 {
    let bottom = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
    Mat4::from_translation(position)
        * Mat4::from_scale(Vec3::splat(scale))
        * Mat4::from_translation(-bottom)
        * Mat4::from_mat3(orient)
}
