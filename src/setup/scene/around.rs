//! A scene with a `[character]` that gives no `[domain]` (or no `[camera]`) gets one fitted
//! around the character's motion: the box its skin sweeps over its clip, its path's lap and
//! the scene's frames, grown by a margin; the camera frames that box from the front three
//! quarters (the side three quarters for a long one). A scene file for a character nobody
//! tuned for then names only the file, the animation, the height and a pool.
use super::character::{perimeter, placed_matrices, CharacterDesc};
use super::schema::{CameraDesc, Domain, Scene};
use crate::character::Skinning;
use crate::character::{check::bounds, Animator, Character};
use crate::error::{Error, Result};
use glam::Vec3;

/// Room around the swept box, in character heights (the pool spreads, water splashes).
const MARGIN: f32 = 0.25;
/// Poses sampled a second of the sweep, and at most in all.
const RATE: f64 = 30.0;
const MAX_SAMPLES: usize = 240;
/// Longest sweep sampled (seconds): a longer clip or lap repeats its ground.
const MAX_SPAN: f64 = 60.0;
/// The fitted camera's field of view (degrees) and its direction from the box's centre:
/// from the front three quarters (+Z is the front), or from the side three quarters when
/// the motion is longer along Z than wide (a quadruped seen from the front hides its body).
const FOV: f32 = 40.0;
const FRONT: Vec3 = Vec3::new(0.55, 0.3, 1.0);
const SIDE: Vec3 = Vec3::new(1.0, 0.3, 0.55);

/// Fit the domain and the camera that `scene` leaves out, when it has a character.
pub fn fit_around(scene: &mut Scene) -> Result<()> {
    let Some(desc) = scene.character.clone() else {
        return Ok(());
    };
    if !scene.domain.is_unset() && scene.camera.is_some() {
        return Ok(());
    }
    let (ch, anim) = desc.load()?;
    let (lo, hi) = swept(scene, &desc, &ch, &anim)?;
    let (rlo, rhi) = super::character::placed_rest_bounds(&ch, &anim)?;
    let height = rhi.y - rlo.y;
    if !(height.is_finite() && height > 0.0) {
        return Err(Error::Param(format!(
            "scene {}: the character has no height to fit a domain around",
            scene.name
        )));
    }
    if scene.domain.is_unset() {
        // The floor is where the rest pose's bottom stands (a foot dipping below it stays
        // in the wall rather than lowering the floor under the others).
        let floor = match desc.path.is_empty() {
            true => desc.position[1],
            false => desc.path.iter().map(|p| p[1]).fold(f32::MAX, f32::min),
        };
        let m = MARGIN * height;
        scene.domain = Domain {
            min: [lo.x - m, floor, lo.z - m],
            max: [hi.x + m, hi.y.max(floor + height) + m, hi.z + m],
        };
    }
    if scene.camera.is_none() {
        let c = 0.5 * (lo + hi);
        let dir = match hi.z - lo.z > hi.x - lo.x {
            true => SIDE.normalize(),
            false => FRONT.normalize(),
        };
        let dist = framing_distance(lo, hi, dir);
        scene.camera = Some(CameraDesc {
            eye: (c + dir * dist).into(),
            target: c.into(),
            fov: FOV,
        });
    }
    Ok(())
}

/// How far from the box's centre along `dir` a camera of [`FOV`] (vertical, and as wide
/// across: frames are at least as wide as high) sees all of [lo, hi], with a little room.
fn framing_distance(lo: Vec3, hi: Vec3, dir: Vec3) -> f32 {
    let c = 0.5 * (lo + hi);
    let right = Vec3::Y.cross(dir).normalize();
    let up = dir.cross(right);
    let tan = (0.5 * FOV.to_radians()).tan() / 1.1;
    // A corner at offset o from the centre is in view from distance d when its sideways
    // and upward offsets are within tan times its depth d - o.dir.
    (0..8)
        .map(|k| {
            let o = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) - c;
            let side = o.dot(right).abs().max(o.dot(up).abs());
            side / tan + o.dot(dir)
        })
        .fold(0.0, f32::max)
}

/// The scene times whose poses play: the longest of the clip, its path's lap and the
/// scene's frames (at most [`MAX_SPAN`] s), [`RATE`] a second (at most [`MAX_SAMPLES`]),
/// from the clip's first frame. The one rule for what must fit: the fitted domain holds the
/// skin at these poses, and the control target checks its particles at the same poses.
pub fn played_times(
    scene: &Scene,
    desc: &CharacterDesc,
    ch: &Character,
    anim: &Animator,
) -> Vec<f64> {
    let speed = desc.speed.max(1e-6) as f64;
    let clip = anim
        .clip
        .map_or(0.0, |c| ch.clips[c].duration as f64 / speed);
    let lap = desc.path().as_ref().map_or(0.0, |(p, v)| match *v > 0.0 {
        true => perimeter(p) / *v as f64,
        false => 0.0,
    });
    let f = &scene.fluid;
    let run = scene.frames as f64 * f.dt as f64 * f.substeps as f64;
    let span = clip.max(lap).max(run).min(MAX_SPAN);
    let samples = ((span * RATE).ceil() as usize).clamp(1, MAX_SAMPLES);
    (0..=samples)
        .map(|k| span * k as f64 / samples as f64)
        .collect()
}

/// The box the placed skin sweeps over the poses that play ([`played_times`]).
fn swept(
    scene: &Scene,
    desc: &CharacterDesc,
    ch: &Character,
    anim: &Animator,
) -> Result<(Vec3, Vec3)> {
    let path = desc.path();
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for t in played_times(scene, desc, ch, anim) {
        let mats = placed_matrices(ch, anim, desc.speed, path.as_ref(), t);
        let weights = anim.morph_weights(ch, (t * desc.speed as f64) as f32);
        let (a, b) = bounds(&ch.skinned_with(&mats, &weights, Skinning::Lbs)?.0);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(Error::Param(format!(
            "scene {}: the character's skin leaves the finite numbers",
            scene.name
        )));
    }
    Ok((lo, hi))
}
