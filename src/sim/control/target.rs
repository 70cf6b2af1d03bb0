//! A scene's control target (TOML `[control]`, switches override): the character's
//! control particles placed and bound in the rest pose, checked against the domain at the
//! poses that play (`fits`), and each frame's pose for them (joint matrices relative to the
//! rest pose, so bound particles follow the animation).
use super::binding;
use super::fits::{self, Plays};
use super::force::{ControlForce, ControlSettings, Pose, ALL_GROUPS};
use super::placement;
use crate::character::Skinning;
use crate::character::{pose, Animator, Character, Mesh, MAX_INFLUENCES};
use crate::control::{Adaptive, BoneWeights, ControlMotion, ControlPreset, Deficit, Placement};
use crate::error::{Error, Result};
use crate::gpu::Context;
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

fn random() -> Placement {
    Placement::Random
}
fn eq8() -> BoneWeights {
    BoneWeights::Eq8
}
fn off() -> Adaptive {
    Adaptive::Off
}
fn thresholds() -> [f32; 2] {
    [0.8, 1.2]
}
fn factors() -> [f32; 2] {
    [2.0, 0.5]
}
fn default_pressure() -> f32 {
    DEFAULT_PRESSURE
}

/// The fidelity preset's velocity term K (1/s), deficit attraction (m/s^2) and damping
/// (1/s), chosen from the runs in `results/<device>/control-fidelity.md`.
pub const FIDELITY_VELOCITY: f32 = 10.0;
pub const FIDELITY_ATTRACTION: f32 = 120.0;
pub const FIDELITY_DAMPING: f32 = 4.0;
/// The fidelity preset's reach of the attraction and damping, in control radii h_c: at 5
/// (was 3) CesiumMan drew his whole pool up (fill 0.97, 90% after 0.42 s, against 0.77
/// and never) and the walker kept his metrics (`results/<device>/control-fidelity.md`).
pub const FIDELITY_REACH: f32 = 5.0;
/// The fidelity preset's time between refreshes of the control's sums (`--control-every`
/// is this over the step, rounded): on the walker, 4 steps of 0.36 ms held every metric of
/// a refresh each step, and with damping 4/s so did 5 (here, on CesiumMan too); 6 more than
/// doubled the speed excess (`results/<device>/control-fidelity.md`).
pub const FIDELITY_REFRESH_S: f32 = 1.8e-3;

/// c_cp when neither the scene nor --control-pressure sets it (with h_c = 2h, the
/// built-in walker fills from a pool in about two seconds).
pub const DEFAULT_PRESSURE: f32 = 6e-4;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlDesc {
    #[serde(default = "random")]
    pub placement: Placement,
    /// Control-particle spacing (default: the fluid's rest spacing).
    #[serde(default)]
    pub spacing: Option<f32>,
    #[serde(default = "eq8")]
    pub bone_weights: BoneWeights,
    /// c_cp.
    #[serde(default = "default_pressure")]
    pub pressure: f32,
    /// h_c (default: twice the fluid's h).
    #[serde(default)]
    pub radius: Option<f32>,
    #[serde(default = "off")]
    pub adaptive: Adaptive,
    /// Adaptive thresholds (fractions of rho_0) and factors below and above them.
    #[serde(default = "thresholds")]
    pub thresholds: [f32; 2],
    #[serde(default = "factors")]
    pub factors: [f32; 2],
    /// K of the velocity term (default: the preset's).
    #[serde(default)]
    pub velocity: Option<f32>,
    /// Defaults of the techniques below and of `velocity` (default: fidelity).
    #[serde(default)]
    pub preset: Option<ControlPreset>,
    /// Deficit attraction (m/s^2), its reach and the damping (1/s) (default: the preset's).
    #[serde(default)]
    pub attraction: Option<f32>,
    #[serde(default)]
    pub reach: Option<f32>,
    #[serde(default)]
    pub damping: Option<f32>,
    #[serde(default)]
    pub motion: Option<ControlMotion>,
    /// What the attraction measures a control particle's deficit against (default: rest
    /// density; see `deficit`).
    #[serde(default)]
    pub deficit: Option<Deficit>,
    /// The controlled group (default: all).
    #[serde(default)]
    pub group: Option<u32>,
    /// Steps between refreshes of the control's sums (default: the preset's).
    #[serde(default)]
    pub every: Option<u32>,
}

impl Default for ControlDesc {
    fn default() -> Self {
        Self {
            placement: random(),
            spacing: None,
            bone_weights: eq8(),
            pressure: DEFAULT_PRESSURE,
            radius: None,
            adaptive: off(),
            thresholds: thresholds(),
            factors: factors(),
            velocity: None,
            preset: None,
            attraction: None,
            reach: None,
            damping: None,
            motion: None,
            deficit: None,
            group: None,
            every: None,
        }
    }
}

impl ControlDesc {
    /// The settings for `fluid`. At a chosen spacing S (`--fluid spacing`, or the one a
    /// character scene picks) c_cp is scaled by (S / S0)^4 against the default spacing
    /// S0: eq. 7's acceleration goes as c_cp / (s_c^3 h_c), so the pull per unit of fluid
    /// stays what it is at S0.
    pub fn settings(&self, fluid: &crate::sph::FluidParams) -> ControlSettings {
        let radius = self.radius.unwrap_or(2.0 * fluid.h);
        let scale = match fluid.spacing {
            Some(s) => (s / crate::sph::FluidParams::default().spacing()).powi(4),
            None => 1.0,
        };
        let mut d = Preset::of(self.preset.unwrap_or(ControlPreset::Fidelity));
        if self.placement == Placement::Rays {
            // Re-placed particles have no velocity: the preset's velocity terms stay off
            // (asked for explicitly, they are refused).
            (d.velocity, d.damping) = (0.0, 0.0);
        }
        ControlSettings {
            pressure: self.pressure * scale,
            radius,
            adaptive: self.adaptive,
            low: self.thresholds[0],
            high: self.thresholds[1],
            up: self.factors[0],
            down: self.factors[1],
            velocity: self.velocity.unwrap_or(d.velocity),
            attraction: self.attraction.unwrap_or(d.attraction),
            reach: self.reach.unwrap_or(d.reach * radius),
            damping: self.damping.unwrap_or(d.damping),
            motion: self.motion.unwrap_or(d.motion),
            group: self.group.unwrap_or(ALL_GROUPS),
            every: self.every.unwrap_or_else(|| match d.refresh_s {
                Some(t) => ((t / fluid.dt).round() as u32).clamp(1, super::cache::MAX_EVERY),
                None => 1,
            }),
        }
    }

    /// The deficit measure: as set, else rest density (the shape's fill, tried as the
    /// fidelity default, held less water at the skin and let it run faster: the walker's
    /// fill 0.95 -> 0.93, speed excess 0.66 -> 3.7 m/s; `results/<device>/control-fidelity.md`).
    /// The shape's fill needs particles inside it: asked for with vertices or rays, it is
    /// refused.
    pub fn deficit(&self) -> Result<Deficit> {
        let interior = self.placement == Placement::Random;
        match self.deficit {
            Some(Deficit::Shape) if !interior => Err(Error::Param(format!(
                "--control-deficit shape measures against the fill of control particles inside the shape: --placement {} has none (use random, or --control-deficit rest)",
                self.placement.as_str()
            ))),
            Some(d) => Ok(d),
            None => Ok(Deficit::Rest),
        }
    }
}

/// The defaults a control preset gives the techniques a target does not set.
struct Preset {
    velocity: f32,
    attraction: f32,
    /// In control radii h_c.
    reach: f32,
    damping: f32,
    motion: ControlMotion,
    /// Simulated time between refreshes of the control's sums (None: every step).
    refresh_s: Option<f32>,
}

impl Preset {
    fn of(p: ControlPreset) -> Self {
        match p {
            ControlPreset::Thesis => Self {
                velocity: 0.0,
                attraction: 0.0,
                reach: 3.0,
                damping: 0.0,
                motion: ControlMotion::Frames,
                refresh_s: None,
            },
            ControlPreset::Fidelity => Self {
                velocity: FIDELITY_VELOCITY,
                attraction: FIDELITY_ATTRACTION,
                reach: FIDELITY_REACH,
                damping: FIDELITY_DAMPING,
                motion: ControlMotion::Skin,
                refresh_s: Some(FIDELITY_REFRESH_S),
            },
        }
    }
}

/// Control particles of a placed character, driving the fluid as a hook lent to the steps.
pub struct ControlTarget {
    pub force: ControlForce,
    pub desc: ControlDesc,
    /// Placed rest-pose joint matrices (the bind of the control particles).
    rest_inv: Vec<Mat4>,
    /// How the control particles (or the rays' surface) are skinned.
    skinning: Skinning,
}

/// The inverses of the placed rest matrices (a singular one cannot bind particles).
fn rest_inverses(ch: &Character, placed_rest: &[Mat4]) -> Result<Vec<Mat4>> {
    placed_rest
        .iter()
        .map(|m| {
            let inv = m.inverse();
            match inv.is_finite() {
                true => Ok(inv),
                false => Err(Error::Model {
                    path: ch.source.clone(),
                    message: "a joint's rest matrix is singular: control particles cannot be bound"
                        .into(),
                }),
            }
        })
        .collect()
}

/// The placed rest pose's joint matrices.
fn placed_rest(ch: &Character, anim: &Animator) -> Vec<Mat4> {
    ch.rest_matrices()
        .iter()
        .map(|m| anim.placement * *m)
        .collect()
}

/// Control particles placed in the placed rest pose and bound to the character's joints,
/// with the inverses of the rest matrices that pose them (what the GPU skins each frame).
pub struct Bound {
    pub mesh: Mesh,
    pub rest_inv: Vec<Mat4>,
    /// The character's mesh in the placed rest pose.
    pub rest_mesh: Vec<Vec3>,
    pub spacing: f32,
}

impl Bound {
    /// Place and bind `desc`'s control particles in `ch` posed by `anim`; `None` for
    /// `--placement rays`, which places in the moving surface every frame instead.
    pub fn new(
        ch: &Character,
        anim: &Animator,
        desc: &ControlDesc,
        fluid: &crate::sph::FluidParams,
        seed: u64,
    ) -> Result<Option<Self>> {
        if desc.placement == Placement::Rays {
            return Ok(None);
        }
        let placed_rest = placed_rest(ch, anim);
        let (rest_mesh, _) = ch.skinned_at(&placed_rest, Skinning::Lbs)?;
        let spacing = desc.spacing.unwrap_or(fluid.spacing());
        let points = placement::place(ch, &rest_mesh, desc.placement, spacing, seed)?;
        let globals: Vec<Mat4> = ch
            .skeleton
            .globals(&ch.skeleton.rest_locals())
            .iter()
            .map(|g| anim.placement * *g)
            .collect();
        let bones = binding::bones(ch, &globals);
        let (joints, weights) = binding::bind(ch, &bones, &points, desc.bone_weights, &rest_mesh);
        let (morphs, points) =
            super::morph_bind::bind(ch, &placed_rest, &rest_mesh, points, spacing)?;
        let sets = match desc.bone_weights {
            BoneWeights::Skin => ch.mesh.influence_sets,
            _ => 1,
        };
        let n = points.len();
        let mesh = Mesh {
            positions: points,
            normals: vec![Vec3::ZERO; n],
            uvs: Vec::new(),
            indices: Vec::new(),
            joints,
            weights,
            influence_sets: sets.min(MAX_INFLUENCES / 4),
            uv_parts: Vec::new(),
            morphs,
        };
        let rest_inv = rest_inverses(ch, &placed_rest)?;
        Ok(Some(Self {
            mesh,
            rest_inv,
            rest_mesh,
            spacing,
        }))
    }

    /// The particles skinned by `method` to placed joint matrices `mats` and morph
    /// weights `weights` (the character's targets').
    pub fn at(
        &self,
        ch: &Character,
        (mats, weights): (&[Mat4], &[f32]),
        method: Skinning,
    ) -> Result<Vec<Vec3>> {
        fits::skin(ch, &self.mesh, &self.rest_inv, (mats, weights), method)
    }
}

impl ControlTarget {
    /// Place and bind control particles in `ch` (posed by `anim`) for fluid searched by
    /// `solver`; refused where they leave the domain at a pose that plays.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        solver: &crate::sph::SphSolver,
        ch: &Character,
        anim: &Animator,
        desc: &ControlDesc,
        fluid: &crate::sph::FluidParams,
        plays: &Plays,
        (seed, skinning): (u64, Skinning),
    ) -> Result<Self> {
        let domain = plays.domain;
        let Some(Bound {
            mesh,
            rest_inv,
            rest_mesh,
            spacing,
        }) = Bound::new(ch, anim, desc, fluid, seed)?
        else {
            // Rays place inside the moving surface itself: all of it must fit.
            fits::check(ch, &ch.mesh, &[], skinning, "surface's vertices", plays)?;
            desc.deficit()?;
            let spacing = desc.spacing.unwrap_or(fluid.spacing());
            let rest_mesh = ch.skinned_at(&placed_rest(ch, anim), Skinning::Lbs)?.0;
            let points = placement::place(ch, &rest_mesh, desc.placement, spacing, seed)?;
            let rest = (spacing, points.len());
            return Self::rays(ctx, solver, ch, desc, fluid, domain, rest, skinning);
        };
        fits::check(ch, &mesh, &rest_inv, skinning, "control particles", plays)?;
        let settings = desc.settings(fluid);
        let fill = match desc.deficit()? {
            Deficit::Shape => {
                let idx = &ch.mesh.indices;
                let closed = ch.check.closed();
                let volume = crate::character::inside::volume(&rest_mesh, idx, spacing, closed).0;
                let volume = volume as f32;
                Some(placement::fill(&mesh.positions, volume, fluid.h))
            }
            Deficit::Rest => None,
        };
        let force = ControlForce::new(
            ctx,
            solver,
            &mesh,
            ch.skeleton.joints.len(),
            settings,
            domain,
            (None, skinning, fill.as_deref()),
        )?;
        Ok(Self {
            force,
            desc: desc.clone(),
            rest_inv,
            skinning,
        })
    }

    /// `--placement rays`: the character's own surface, skinned by its own weights and
    /// re-placed on the GPU every frame; room for three times the rest pose's lattice
    /// (`rest` points).
    #[allow(clippy::too_many_arguments)]
    fn rays(
        ctx: &Context,
        solver: &crate::sph::SphSolver,
        ch: &Character,
        desc: &ControlDesc,
        fluid: &crate::sph::FluidParams,
        domain: ([f32; 3], [f32; 3]),
        (spacing, rest): (f32, usize),
        skinning: Skinning,
    ) -> Result<Self> {
        let capacity = (3 * rest + 1024).min(u32::MAX as usize / 16) as u32;
        let force = ControlForce::new(
            ctx,
            solver,
            &ch.mesh,
            ch.skeleton.joints.len(),
            desc.settings(fluid),
            domain,
            (Some((spacing, capacity)), skinning, None),
        )?;
        Ok(Self {
            force,
            desc: desc.clone(),
            rest_inv: Vec::new(),
            skinning,
        })
    }

    /// Set the pose of scene time `t` (the animator's joint matrices, placed, and morph
    /// weights) for the next frame's steps, `frame_dt` seconds after the previous pose;
    /// `next`: the pose a frame ahead (`--control-motion skin`).
    pub fn set_pose(
        &mut self,
        ch: &Character,
        (mats, weights): (&[Mat4], &[f32]),
        next: Option<(&[Mat4], &[f32])>,
        frame_dt: f32,
    ) -> Result<()> {
        let name = |j: usize| ch.joint_name(j);
        let joints = |m: &[Mat4]| -> Result<_> {
            if self.desc.placement == Placement::Rays {
                // The surface itself is skinned (its bind pose is the file's).
                return pose::gpu_joints(m, self.skinning, &name);
            }
            let rel: Vec<Mat4> = m.iter().zip(&self.rest_inv).map(|(m, r)| *m * *r).collect();
            pose::gpu_joints(&rel, self.skinning, &name)
        };
        let next = match next {
            Some((n, w)) if self.desc.placement != Placement::Rays => {
                Some((joints(n)?, w.to_vec()))
            }
            _ => None,
        };
        self.force.set_pose(Pose {
            joints: joints(mats)?,
            weights: weights.to_vec(),
            frame_dt,
            next,
        });
        Ok(())
    }

    pub fn count(&self) -> u32 {
        self.force.m
    }
}
