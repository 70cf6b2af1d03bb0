//! A character in a scene (TOML `[character]`): which file and clip, where it stands, how
//! fast it plays; skinned every frame on the GPU (`skin` scope) and drawn by the view.
use crate::character::{self, anim, anim::Up, Animator, Character};
use crate::error::{Error, Result};
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

fn yes() -> bool {
    true
}

fn one() -> f32 {
    1.0
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CharacterDesc {
    /// A .glb, .gltf or .obj file (relative to the scene file) or builtin:walker|giraffe.
    pub file: String,
    /// Clip name or index (default: the first, if the file has any).
    #[serde(default)]
    pub animation: Option<String>,
    /// Loop the clip (else hold its last pose).
    #[serde(default = "yes")]
    pub looping: bool,
    /// The file's up axis ("y", glTF's; "z" for a Z-up OBJ; "-z", "x", "-x", "-y"),
    /// turned to +Y before `rotation` and `height`.
    #[serde(default)]
    pub up: Up,
    /// Scale the rest pose to this height in metres (standing as `up` and `rotation` turn
    /// it) ...
    #[serde(default)]
    pub height: Option<f32>,
    /// ... or by this factor (default 1: the file's units, metres for glTF).
    #[serde(default)]
    pub scale: Option<f32>,
    /// Where the rest pose's bottom centre stands.
    #[serde(default)]
    pub position: [f32; 3],
    /// XYZ Euler angles in degrees after `up`; the turned rest pose's bottom centre then
    /// stands at `position`.
    #[serde(default)]
    pub rotation: [f32; 3],
    /// Playback rate (1: the clip's own timing).
    #[serde(default = "one")]
    pub speed: f32,
    /// Waypoints of a closed loop the rest pose's bottom centre follows at `path_speed`,
    /// turned to face along it (+Z forward after `rotation`); `position` is then unused.
    #[serde(default)]
    pub path: Vec<[f32; 3]>,
    /// Metres per second along `path`.
    #[serde(default)]
    pub path_speed: f32,
}

/// The length of the closed loop through `points`.
pub fn perimeter(points: &[Vec3]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| points[i].distance(points[(i + 1) % n]) as f64)
        .sum()
}

/// Where on a closed loop through `points` a walker at `speed` is after `t` seconds, and
/// its heading (yaw about +Y from +Z).
pub fn path_pose(points: &[Vec3], speed: f32, t: f64) -> (Vec3, f32) {
    let n = points.len();
    if n < 2 {
        return (points.first().copied().unwrap_or(Vec3::ZERO), 0.0);
    }
    let seg = |i: usize| (points[i], points[(i + 1) % n]);
    let perimeter = perimeter(points);
    let mut d = match perimeter > 0.0 {
        true => (speed as f64 * t).rem_euclid(perimeter),
        false => 0.0,
    };
    for i in 0..n {
        let (a, b) = seg(i);
        let l = a.distance(b) as f64;
        if d <= l || i == n - 1 {
            let dir = (b - a).normalize_or_zero();
            let at = a + dir * d.min(l) as f32;
            return (at, dir.x.atan2(dir.z));
        }
        d -= l;
    }
    (points[0], 0.0)
}

/// The placed joint matrices of `ch` at scene time `t`: the clip at `speed`, then along
/// `path` (waypoints, metres per second) when it has one.
pub fn placed_matrices(
    ch: &Character,
    anim: &Animator,
    speed: f32,
    path: Option<&(Vec<Vec3>, f32)>,
    t: f64,
) -> Vec<Mat4> {
    let mats = anim.joint_matrices(ch, (t * speed as f64) as f32);
    match path {
        None => mats,
        Some((points, speed)) => {
            let (at, yaw) = path_pose(points, *speed, t);
            let m = Mat4::from_translation(at) * Mat4::from_rotation_y(yaw);
            mats.into_iter().map(|x| m * x).collect()
        }
    }
}

impl CharacterDesc {
    /// `file` at its own size at the origin, its first clip looping at its own rate.
    pub fn new(file: &str) -> Self {
        Self {
            file: file.into(),
            animation: None,
            looping: true,
            height: None,
            scale: None,
            position: [0.0; 3],
            up: Up::Y,
            rotation: [0.0; 3],
            speed: 1.0,
            path: Vec::new(),
            path_speed: 0.0,
        }
    }

    /// The path's waypoints and speed, when it has one.
    pub fn path(&self) -> Option<(Vec<Vec3>, f32)> {
        (!self.path.is_empty()).then(|| {
            (
                self.path.iter().map(|p| Vec3::from(*p)).collect(),
                self.path_speed,
            )
        })
    }

    pub fn validate(&self, scene: &str) -> Result<()> {
        let bad = |m: String| Err(Error::Param(format!("scene {scene}: character {m}")));
        if self.height.is_some() && self.scale.is_some() {
            return bad("takes height or scale, not both".into());
        }
        for (k, v) in [("height", self.height), ("scale", self.scale)] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return bad(format!("{k} must be positive, got {v}"));
            }
        }
        if !(self.speed.is_finite() && self.speed >= 0.0) {
            return bad(format!("speed must be at least 0, got {}", self.speed));
        }
        if !(self.path_speed.is_finite() && self.path_speed >= 0.0) {
            return bad(format!(
                "path_speed must be at least 0, got {}",
                self.path_speed
            ));
        }
        if self.path.iter().flatten().any(|v| !v.is_finite()) {
            return bad("path points must be finite".into());
        }
        if self.path_speed > 0.0 && self.path.len() < 2 {
            return bad("path_speed needs a path of at least 2 points".into());
        }
        if self
            .position
            .iter()
            .chain(&self.rotation)
            .any(|v| !v.is_finite())
        {
            return bad("position and rotation must be finite".into());
        }
        Ok(())
    }

    /// The file's up axis then `rotation`, as one rotation.
    pub fn orientation(&self) -> glam::Mat3 {
        anim::orientation(self.up, self.rotation.into())
    }

    /// The loaded character and its animator (clip chosen, placement made).
    pub fn load(&self) -> Result<(Character, Animator)> {
        let ch = character::load(&self.file)?;
        if self.animation.is_some() && ch.clips.is_empty() && !ch.skinned {
            ch.require_skin("an animation")?;
        }
        let clip = match &self.animation {
            Some(sel) => Some(ch.clip_index(sel)?),
            None => (!ch.clips.is_empty()).then_some(0),
        };
        let rest = ch.rest_positions()?;
        let orient = self.orientation();
        let (lo, hi) = anim::turned_bounds(&rest, orient);
        let s = match (self.height, self.scale) {
            (Some(h), _) => h / (hi.y - lo.y).max(1e-9),
            (_, Some(s)) => s,
            _ => 1.0,
        };
        let at = match self.path.is_empty() {
            true => self.position.into(),
            false => Vec3::ZERO, // the path places it each frame
        };
        let placement = anim::stand((lo, hi), orient, s, at);
        let animator = Animator {
            clip,
            looping: self.looping,
            placement,
        };
        Ok((ch, animator))
    }
}

/// The bounds of `ch`'s rest pose as `anim` places it.
pub fn placed_rest_bounds(ch: &Character, anim: &Animator) -> Result<(Vec3, Vec3)> {
    let p = ch.rest_positions()?;
    let placed: Vec<Vec3> = p
        .iter()
        .map(|v| anim.placement.transform_point3(*v))
        .collect();
    Ok(character::check::bounds(&placed))
}
