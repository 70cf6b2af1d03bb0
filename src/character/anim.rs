//! Clip sampling (glTF 2.0 §3.11 and Appendix C): STEP, LINEAR (rotations by shortest-path
//! slerp) and CUBICSPLINE (Hermite with tangents scaled by the key interval), looping or
//! clamped; then node globals and joint matrices.
use super::model::{Channel, Clip, Interp, Property, Skeleton, Trs};
use glam::{Mat4, Quat, Vec3, Vec4};

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
            }
        }
        locals
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

/// Placement: scale, then rotation (XYZ Euler degrees), then translation.
pub fn placement(scale: f32, rotation_deg: Vec3, position: Vec3) -> Mat4 {
    let r = Quat::from_euler(
        glam::EulerRot::XYZ,
        rotation_deg.x.to_radians(),
        rotation_deg.y.to_radians(),
        rotation_deg.z.to_radians(),
    );
    Mat4::from_scale_rotation_translation(Vec3::splat(scale), r, position)
}
