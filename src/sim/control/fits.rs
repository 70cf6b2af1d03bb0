//! What a control target must fit: its particles (or, placed by rays, its surface) where
//! they will be, skinned to the poses that play, not where they are placed. A bind pose
//! wider than its clip (a T-pose whose arms hang down in the walk) places its particles in
//! the bind pose and is checked at the clip's poses, by the same rule the fitted domain is
//! sized by (the scene's `played_times`).
use crate::character::{cpu, pose, Character, Mesh, Skinning};
use crate::error::{Error, Result};
use glam::{Mat4, Vec3};

/// How far into the domain's floor and walls a character may reach, in its heights (a
/// foot dipping into the floor, a hand into a wall): the scene's first-pose check and
/// [`Plays::slack`] both allow it.
pub const DIP: f32 = 0.1;

/// The domain a control target must stay in, and the poses that play: (scene time in
/// seconds, placed joint matrices), from the clip's first frame.
pub struct Plays<'a> {
    pub domain: ([f32; 3], [f32; 3]),
    /// How far a point may reach past the domain's faces (metres): a tenth of the
    /// character's height, as the scene's first-pose check lets a foot dip into the floor
    /// and a hand into a wall.
    pub slack: f32,
    /// With each pose's morph weights (the character's targets').
    pub poses: &'a [(f64, Vec<Mat4>, Vec<f32>)],
    /// Seconds a frame advances (to name the frame of a pose that does not fit).
    pub frame_s: f64,
}

/// `mesh` (control particles bound to `ch`'s joints, or `ch`'s own mesh when `rest_inv`
/// is empty) skinned by `method` to placed joint matrices `mats` with morph weights
/// `weights` (empty: the targets' defaults), as the GPU skins it.
pub fn skin(
    ch: &Character,
    mesh: &Mesh,
    rest_inv: &[Mat4],
    (mats, weights): (&[Mat4], &[f32]),
    method: Skinning,
) -> Result<Vec<Vec3>> {
    let rel: Vec<Mat4> = match rest_inv.is_empty() {
        true => mats.to_vec(),
        false => mats.iter().zip(rest_inv).map(|(m, r)| *m * *r).collect(),
    };
    let joints = pose::gpu_joints(&rel, method, &|j| ch.joint_name(j))?;
    let targets = mesh.morphs.targets.len();
    let weights = match weights.len() {
        0 => mesh.morphs.defaults(),
        n if n == targets => weights.to_vec(),
        n => {
            return Err(Error::Param(format!(
                "{n} morph weights for {targets} morph targets of {}",
                ch.source
            )))
        }
    };
    Ok(cpu::skin(method, &joints, mesh, &weights).0)
}

/// `mesh` (control particles bound to `ch`'s joints, or `ch`'s own mesh when `rest_inv`
/// is empty) skinned by `method` to every pose of `plays`: the first pose where a point
/// leaves the domain is refused in one line naming its time and frame, the joint that
/// carries the point farthest out, by how much and which way, and how to widen the domain.
pub fn check(
    ch: &Character,
    mesh: &Mesh,
    rest_inv: &[Mat4],
    method: Skinning,
    what: &str,
    plays: &Plays,
) -> Result<()> {
    let (lo, hi) = (Vec3::from(plays.domain.0), Vec3::from(plays.domain.1));
    let slack = plays.slack.max(0.0);
    for (t, mats, weights) in plays.poses {
        let points = skin(ch, mesh, rest_inv, (mats, weights), method)?;
        let out = |p: &Vec3| (lo - *p).max(*p - hi).max_element();
        let Some((v, p)) = points
            .iter()
            .enumerate()
            .max_by(|a, b| out(a.1).total_cmp(&out(b.1)))
        else {
            return Ok(());
        };
        if out(p) <= slack {
            continue;
        }
        let k = 4 * mesh.influence_sets;
        let joint = (0..k)
            .max_by(|&a, &b| mesh.weights[v][a].total_cmp(&mesh.weights[v][b]))
            .map(|i| ch.joint_name(mesh.joints[v][i] as usize))
            .unwrap_or_else(|| "the root".into());
        let axis = (lo - *p)
            .max(*p - hi)
            .to_array()
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or(0, |(i, _)| i);
        let side = match p[axis] < lo[axis] {
            true => format!("below {}", lo[axis]),
            false => format!("above {}", hi[axis]),
        };
        let frame = (t / plays.frame_s.max(1e-9)).round() as u64;
        return Err(Error::Param(format!(
            "the control target {}: at {t:.2} s (frame {frame}) its {what} carried by joint \
             '{joint}' reach {:.3} m outside the domain {lo}..{hi} ({} = {} is {side}; {slack:.3} m \
             may dip in); widen the scene's [domain], or leave it out to fit one around the poses \
             that play",
            ch.source,
            out(p),
            ["x", "y", "z"][axis],
            p[axis],
        )));
    }
    Ok(())
}
