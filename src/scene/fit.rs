//! A liquid character's scene fitted to its character: the particle spacing from the
//! character's thinnest part when the scene and the switches give none, and `[pool]`, the
//! water it is made of, sized from its volume and laid under its first pose.
use super::character::placed_matrices;
use crate::character::inspect::thinnest;
use crate::error::{Error, Result};
use crate::scene::schema::{white, Block, Scene};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Particles across the thinnest part at the chosen spacing.
pub const ACROSS: f32 = 2.5;
/// The chosen spacing stays within [height / FINEST, height / COARSEST].
pub const FINEST: f32 = 70.0;
pub const COARSEST: f32 = 35.0;
/// The chosen spacing puts at most about this many particles in the pool: a character whose
/// thinnest part is thin for its size (a quadruped's feet) would otherwise take tens of
/// thousands of particles and tiny steps (the fox: 28.7K at 74 steps a frame), beyond what
/// a 2-core machine plays in minutes. `--fluid spacing=S` goes finer.
pub const BUDGET: f32 = 8192.0;

/// The default pool holds this many times the character's volume: 1.15 (was 1.3) once the
/// attraction's reach of 5 h_c drew the whole pool up: the 0.3 spare then sat as a lump on
/// a leg (CesiumMan's iou 0.67 at 1.3, 0.74 at 1.15; results/<device>/control-fidelity.md).
fn volume() -> f32 {
    1.15
}

/// `[pool]`: a block of water on the floor under the character's first pose (its
/// footprint grown by a smoothing length), holding `volume` times the character's volume.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoolDesc {
    #[serde(default = "volume")]
    pub volume: f32,
    #[serde(default = "white")]
    pub color: [f32; 3],
}

impl Default for PoolDesc {
    fn default() -> Self {
        Self {
            volume: volume(),
            color: white(),
        }
    }
}

/// What the fitting chose, printed at the start of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fitted {
    /// The spacing chosen (metres) and why, when the scene and switches gave none.
    pub spacing: Option<(f32, String)>,
    /// The pool's block and particle count.
    pub pool: Option<(Block, u64)>,
}

impl Fitted {
    pub fn describe(&self) -> Vec<String> {
        let mut out = Vec::new();
        if let Some((s, why)) = &self.spacing {
            out.push(format!(
                "spacing {s:.4} m ({why}; --fluid spacing=S overrides)"
            ));
        }
        if let Some((b, n)) = &self.pool {
            let d: Vec<String> = (0..3)
                .map(|k| format!("{:.3}", b.max[k] - b.min[k]))
                .collect();
            out.push(format!("pool {} m, {n} particles", d.join(" x ")));
        }
        out
    }
}

/// Fit `scene` (its fluid already has the switches' overrides) to its `[character]` when
/// it has control targets: a spacing unless one is set (or a mass other than the
/// default's), then the pool.
pub fn fit(scene: &mut Scene) -> Result<Fitted> {
    let mut out = Fitted {
        spacing: None,
        pool: None,
    };
    let Some(desc) = scene.character.clone() else {
        if scene.pool.is_some() {
            return Err(Error::Param(format!(
                "scene {}: [pool] is sized from [character], which it lacks",
                scene.name
            )));
        }
        return Ok(out);
    };
    if scene.control_targets().is_empty() && scene.pool.is_none() {
        return Ok(out);
    }
    let (ch, anim) = desc.load()?;
    let (lo, hi) = ch.rest_bounds()?;
    let scale = anim.placement.x_axis.truncate().length();
    let height = (hi.y - lo.y) * scale;
    let volume = (ch.check.signed_volume.abs() as f32) * scale.powi(3);
    // (A mass other than the default's already says the spacing: mass = rho_0 S^3.)
    let default_mass = scene.fluid.mass == crate::sph::FluidParams::default().mass;
    if scene.fluid.spacing.is_none() && default_mass {
        let pool = scene.pool.as_ref().map_or(1.0, |p| p.volume);
        // The spacing the thinnest part asks for, and that part's name and width.
        let (s, part) = match thinnest(&ch) {
            Some(t) => {
                let d = t.diameter * scale;
                let s = (d / ACROSS).clamp(height / FINEST, height / COARSEST);
                (s, Some((t.joint, d)))
            }
            None => (height / COARSEST, None),
        };
        // (A spacing the budget coarsens still stays within height / COARSEST.)
        let budget = (volume * pool / BUDGET).cbrt().min(height / COARSEST);
        let why = match (budget > s, part) {
            (true, _) => format!(
                "the pool held to about {BUDGET} particles: {s:.4} m would give {:.0}",
                volume * pool / s.powi(3)
            ),
            (false, None) => format!("height / {COARSEST}"),
            (false, Some((joint, d))) => format!(
                "{:.2} across the thinnest part, '{joint}' {d:.4} m, within height / {FINEST} .. height / {COARSEST}",
                d / s
            ),
        };
        let s = s.max(budget);
        scene.fluid.spacing = Some(s);
        scene.fluid.resolve_spacing()?;
        out.spacing = Some((s, why));
    }
    if let Some(pool) = scene.pool.take() {
        if !(pool.volume.is_finite() && pool.volume > 0.0 && pool.volume <= 20.0) {
            return Err(Error::Param(format!(
                "scene {}: [pool] volume is times the character's volume, in (0, 20], got {}",
                scene.name, pool.volume
            )));
        }
        // The placed skin at scene time 0 (the path's start included).
        let mats = placed_matrices(&ch, &anim, desc.speed, desc.path().as_ref(), 0.0);
        let first = ch.skinned_at(&mats, crate::config::Skinning::Lbs)?.0;
        // Under the lower half of the body only: arms held out (a T-pose) would spread the
        // pool beyond the attraction's reach of the legs, leaving puddles under the hands.
        let (lo, _) = crate::character::check::bounds(&first);
        let low: Vec<Vec3> = first
            .iter()
            .copied()
            .filter(|p| p.y <= lo.y + 0.5 * height)
            .collect();
        let (plo, phi) = crate::character::check::bounds(&low);
        let want = volume * pool.volume;
        let b = pool_block(scene, (plo, phi), want, pool.color)?;
        let s = scene.fluid.spacing();
        let n: u64 = (0..3)
            .map(|k| ((b.max[k] - b.min[k]) / s).floor() as u64)
            .product();
        scene.blocks.push(b.clone());
        out.pool = Some((b, n));
    }
    Ok(out)
}

/// A block on the domain's floor under [lo, hi] (grown by h) deep enough for `want` m^3
/// of particles on the rest lattice.
fn pool_block(scene: &Scene, (lo, hi): (Vec3, Vec3), want: f32, color: [f32; 3]) -> Result<Block> {
    let (dlo, dhi) = (scene.domain.min, scene.domain.max);
    let (s, h) = (scene.fluid.spacing(), scene.fluid.h);
    let mut min = [0.0; 3];
    let mut max = [0.0; 3];
    for k in [0, 2] {
        min[k] = (lo[k] - h).max(dlo[k]);
        max[k] = (hi[k] + h).min(dhi[k]);
    }
    let across = |k: usize| ((max[k] - min[k]) / s).floor();
    let cells = across(0) * across(2);
    if cells < 1.0 {
        return Err(Error::Param(format!(
            "scene {}: the character stands outside the domain: no room for [pool]",
            scene.name
        )));
    }
    let layers = (want / (s * s * s) / cells).ceil().max(1.0);
    min[1] = dlo[1];
    max[1] = dlo[1] + layers * s;
    if max[1] > dhi[1] {
        return Err(Error::Param(format!(
            "scene {}: [pool] needs {:.3} m of water under the character, higher than the domain ({:.3} m): widen the domain or lower the volume",
            scene.name,
            layers * s,
            dhi[1] - dlo[1]
        )));
    }
    Ok(Block {
        min,
        max,
        group: 0,
        color,
        velocity: [0.0; 3],
    })
}
