//! A liquid character's scene fitted to its character: the particle spacing from the
//! character's thinnest part when the scene and the switches give none, and `[pool]`, the
//! water it is made of, sized from its volume and laid under its first pose.
use super::character::{placed_matrices, placed_rest_bounds};
use crate::character::thickness::{regions, Region};
use crate::error::{Error, Result};
use crate::scene::schema::{white, Block, Scene};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Particles across the thinnest part at the chosen spacing.
pub const ACROSS: f32 = 3.0;
/// The chosen spacing stays within [height / FINEST, height / COARSEST].
pub const FINEST: f32 = 70.0;
pub const COARSEST: f32 = 35.0;
/// The chosen spacing puts at most about this many particles in the pool (`[pool]
/// particles` sets it per scene): a character whose
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
    /// At most about this many particles: a fitted spacing coarsens to hold it.
    #[serde(default = "budget")]
    pub particles: f32,
}

fn budget() -> f32 {
    BUDGET
}

impl Default for PoolDesc {
    fn default() -> Self {
        Self {
            volume: volume(),
            color: white(),
            particles: BUDGET,
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
    /// The parts the chosen spacing leaves under [`WANT`] spacings across, in one line.
    pub thin: Option<String>,
    /// An open mesh's counts and how its volume was measured, in one line.
    pub open: Option<String>,
    /// The clip that plays and the parts that are open, in one line.
    pub character: Option<String>,
}

impl Fitted {
    pub fn describe(&self) -> Vec<String> {
        let mut out: Vec<String> = self.character.iter().cloned().collect();
        out.extend(self.open.clone());
        if let Some((s, why)) = &self.spacing {
            out.push(format!(
                "spacing {s:.4} m ({why}; --fluid spacing=S overrides)"
            ));
        }
        out.extend(self.thin.clone());
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
        thin: None,
        open: None,
        character: None,
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
    out.character = Some(plays(&ch, &anim));
    let (lo, hi) = placed_rest_bounds(&ch, &anim)?;
    let scale = anim.placement.x_axis.truncate().length();
    let height = hi.y - lo.y;
    // An open mesh's volume: its winding number's voxels at the finest spacing the fit
    // may choose (a closed one's signed volume, exact, as always).
    let started = std::time::Instant::now();
    let rest = ch.rest_positions()?;
    let side = height / scale / FINEST;
    let closed = ch.check.closed();
    let (volume, voxels) = crate::character::inside::volume(&rest, &ch.mesh.indices, side, closed);
    let volume = volume as f32 * scale.powi(3);
    out.open = voxels.map(|(n, side)| {
        format!(
            "open mesh ({}): volume {volume:.4} m^3 from {n} voxels of {:.4} m inside by the winding number, in {:.0} ms",
            ch.check.describe(),
            side as f32 * scale,
            started.elapsed().as_secs_f64() * 1e3
        )
    });
    // The placed skin at scene time 0 (the path's start included).
    let mats = placed_matrices(&ch, &anim, desc.speed, desc.path().as_ref(), 0.0);
    let first = ch.skinned_at(&mats, crate::character::Skinning::Lbs)?.0;
    inside(scene, &first, height)?;
    // (A mass other than the default's already says the spacing: mass = rho_0 S^3.)
    let default_mass = scene.fluid.mass == crate::sph::FluidParams::default().mass;
    if scene.fluid.spacing.is_none() && default_mass {
        let (pool, most) = scene
            .pool
            .as_ref()
            .map_or((1.0, BUDGET), |p| (p.volume, p.particles));
        if !(most.is_finite() && most >= 64.0) {
            return Err(Error::Param(format!(
                "scene {}: [pool] particles is the most the fitted spacing allows, at least 64, got {most}",
                scene.name
            )));
        }
        let parts = regions(&ch, desc.orientation())?;
        // The spacing the thinnest part asks for.
        let s = match parts.first() {
            Some(t) => (t.thickness * scale / ACROSS).clamp(height / FINEST, height / COARSEST),
            None => height / COARSEST,
        };
        // (A spacing the budget coarsens still stays within height / COARSEST.)
        let budget = (volume * pool / most).cbrt().min(height / COARSEST);
        let why = match (budget > s, parts.first()) {
            (true, _) => format!(
                "the pool held to about {most} particles ([pool] particles): {s:.4} m would give {:.0}",
                volume * pool / s.powi(3)
            ),
            (false, None) => format!("height / {COARSEST}"),
            (false, Some(t)) => format!(
                "{:.2} across the thinnest part, '{}' {:.4} m, within height / {FINEST} .. height / {COARSEST}",
                t.thickness * scale / s,
                t.name,
                t.thickness * scale
            ),
        };
        let s = s.max(budget);
        scene.fluid.spacing = Some(s);
        scene.fluid.resolve_spacing()?;
        out.spacing = Some((s, why));
        out.thin = thin(&parts, scale, s, volume * pool);
    }
    if let Some(pool) = scene.pool.take() {
        if !(pool.volume.is_finite() && pool.volume > 0.0 && pool.volume <= 20.0) {
            return Err(Error::Param(format!(
                "scene {}: [pool] volume is times the character's volume, in (0, 20], got {}",
                scene.name, pool.volume
            )));
        }
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

/// Parts are wanted at least this many spacings across (fewer: the fit says so).
pub const WANT: f32 = 3.0;

/// One line naming the parts under [`WANT`] spacings at spacing `s` (thickness in the
/// file's units times `scale`), with the spacing that would fit the thinnest and its
/// pool's particles (`water` m^3).
fn thin(parts: &[Region], scale: f32, s: f32, water: f32) -> Option<String> {
    let under: Vec<&Region> = parts
        .iter()
        .filter(|r| r.thickness * scale < WANT * s)
        .collect();
    let shown: Vec<String> = under
        .iter()
        .take(SHOWN)
        .map(|r| {
            let fits = r.thickness * scale / WANT;
            format!(
                "'{}' {:.1} ({WANT} at {fits:.4} m: {:.1}K particles)",
                r.name,
                r.thickness * scale / s,
                water / fits.powi(3) / 1000.0
            )
        })
        .collect();
    let more = match under.len().saturating_sub(SHOWN) {
        0 => String::new(),
        k => format!(" and {k} more (inspect FILE lists them)"),
    };
    (!under.is_empty()).then(|| {
        format!(
            "under {WANT} spacings across at {s:.4} m: {}{more}; --fluid spacing=S or [pool] particles=N goes finer",
            shown.join(", ")
        )
    })
}

/// Which clip plays and which parts are open (the first few named).
fn plays(ch: &crate::character::Character, anim: &crate::character::Animator) -> String {
    let clip = match anim.clip {
        Some(c) => format!("clip '{}'", ch.clips[c].name),
        None => "no clip (the rest pose)".into(),
    };
    let open = ch.open_parts();
    let parts = ch.parts.len().max(1);
    let named: Vec<&str> = open.iter().take(SHOWN_OPEN).map(String::as_str).collect();
    let more = match open.len().saturating_sub(SHOWN_OPEN) {
        0 => String::new(),
        k => format!(" and {k} more (inspect FILE lists them)"),
    };
    match open.is_empty() {
        true => format!("{} plays {clip}; closed ({parts} parts)", ch.source),
        false => format!(
            "{} plays {clip}; {} of {parts} parts open: {}{more}",
            ch.source,
            open.len(),
            named.join(", ")
        ),
    }
}

/// Open parts named by the fit's line.
const SHOWN_OPEN: usize = 4;

/// Parts named by the fit's line on thin parts.
const SHOWN: usize = 3;

use crate::control::fits::DIP;

/// The character's first pose `first` must stand in the domain: a clear error naming the
/// key to change when it does not (a foot may dip a tenth of its height into the floor, a
/// hand as far into a wall).
fn inside(scene: &Scene, first: &[Vec3], height: f32) -> Result<()> {
    let (lo, hi) = crate::character::check::bounds(first);
    let (dlo, dhi) = (Vec3::from(scene.domain.min), Vec3::from(scene.domain.max));
    let name = &scene.name;
    if lo.y < dlo.y - DIP * height {
        return Err(Error::Param(format!(
            "scene {name}: the character reaches {:.3} m below the domain's floor (y = {}): raise [character] position's y, or set [character] up if the file is not Y-up (inspect FILE --up z --picture PNG shows it standing)",
            dlo.y - lo.y,
            dlo.y
        )));
    }
    // (A hand or a nose a little past a wall stays in it, as a foot in the floor.)
    let slack = Vec3::splat(DIP * height);
    if lo.cmplt(dlo - slack).any() || hi.cmpgt(dhi + slack).any() {
        return Err(Error::Param(format!(
            "scene {name}: the character's first pose spans {lo:.3}..{hi:.3}, outside the domain {dlo}..{dhi}: move [character] position, widen [domain], or leave [domain] out to fit it"
        )));
    }
    Ok(())
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
