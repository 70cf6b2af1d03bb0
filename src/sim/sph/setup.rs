//! What the SPH core is given to run: a domain box, the fluid's parameters and the
//! colliders ([`SphSetup`]), and the initial particles, filled on a lattice at the rest
//! spacing from boxes and balls of fluid. The scene schema above it says where these come
//! from; the solver needs nothing else.
use super::params::{Collider, FluidParams, MAX_COLLIDERS};
use crate::error::{Error, Result};
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

/// The box the fluid lives in. The default, all zeros, stands for "not given": a scene
/// with a character has one fitted around its motion (`scene::fit`), any other is refused.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

impl Domain {
    pub fn is_unset(&self) -> bool {
        *self == Self::default()
    }
}

pub fn white() -> [f32; 3] {
    [0.25, 0.55, 1.0]
}

/// An axis-aligned box of fluid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Block {
    pub min: [f32; 3],
    pub max: [f32; 3],
    #[serde(default)]
    pub group: u32,
    #[serde(default = "white")]
    pub color: [f32; 3],
    #[serde(default)]
    pub velocity: [f32; 3],
}

/// A ball of fluid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ball {
    pub center: [f32; 3],
    pub radius: f32,
    #[serde(default)]
    pub group: u32,
    #[serde(default = "white")]
    pub color: [f32; 3],
    #[serde(default)]
    pub velocity: [f32; 3],
}

/// A fill region: box bounds, inside test, group, colour, velocity.
type Region = (
    [f32; 3],
    [f32; 3],
    Box<dyn Fn([f32; 3]) -> bool>,
    u32,
    [f32; 3],
    [f32; 3],
);

/// Initial particles: positions (xyz, w = 0), velocities, colours (rgb, w = group bits).
pub struct Particles {
    pub pos: Vec<[f32; 4]>,
    pub vel: Vec<[f32; 4]>,
    pub attr: Vec<[f32; 4]>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
}

/// The fluid's frame: everything the solver needs besides the particles.
#[derive(Clone, Copy, Debug)]
pub struct SphSetup<'a> {
    /// For messages.
    pub name: &'a str,
    pub domain: &'a Domain,
    pub fluid: &'a FluidParams,
    pub colliders: &'a [Collider],
}

impl SphSetup<'_> {
    /// The fluid's parameters, a non-empty finite domain and at most
    /// [`MAX_COLLIDERS`] valid colliders.
    pub fn validate(&self) -> Result<()> {
        self.fluid.validate()?;
        let (lo, hi) = (self.domain.min, self.domain.max);
        if (0..3)
            .any(|k| hi[k].is_nan() || hi[k] <= lo[k] || !lo[k].is_finite() || !hi[k].is_finite())
        {
            return Err(Error::Param(format!(
                "scene {}: empty domain {lo:?}..{hi:?}",
                self.name
            )));
        }
        if self.colliders.len() > MAX_COLLIDERS {
            return Err(Error::Param(format!(
                "scene {}: {} colliders, at most {MAX_COLLIDERS}",
                self.name,
                self.colliders.len()
            )));
        }
        for c in self.colliders {
            c.to_gpu()?;
        }
        Ok(())
    }
}

/// Fill `blocks` and `balls` on a cubic lattice at `spacing`, jittered by 1% of it
/// (seeded), keeping points inside `domain` and outside `colliders`.
pub fn fill(
    spacing: f32,
    domain: &Domain,
    (blocks, balls): (&[Block], &[Ball]),
    colliders: &[Collider],
    seed: u64,
) -> Particles {
    let s = spacing;
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut out = Particles {
        pos: Vec::new(),
        vel: Vec::new(),
        attr: Vec::new(),
    };
    let mut regions: Vec<Region> = Vec::new();
    for b in blocks {
        regions.push((
            b.min,
            b.max,
            Box::new(|_| true),
            b.group,
            b.color,
            b.velocity,
        ));
    }
    for b in balls {
        let (c, r) = (b.center, b.radius);
        let inside = move |p: [f32; 3]| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f32>() <= r * r;
        regions.push((
            [c[0] - r, c[1] - r, c[2] - r],
            [c[0] + r, c[1] + r, c[2] + r],
            Box::new(inside),
            b.group,
            b.color,
            b.velocity,
        ));
    }
    let (dlo, dhi) = (domain.min, domain.max);
    for (lo, hi, inside, group, color, vel) in regions {
        let count = |k: usize| (((hi[k] - lo[k]) / s).floor() as i64).max(0);
        for iz in 0..count(2) {
            for iy in 0..count(1) {
                for ix in 0..count(0) {
                    let mut p = [
                        lo[0] + (ix as f32 + 0.5) * s,
                        lo[1] + (iy as f32 + 0.5) * s,
                        lo[2] + (iz as f32 + 0.5) * s,
                    ];
                    if !inside(p) {
                        continue;
                    }
                    for v in &mut p {
                        *v += rng.random_range(-0.01..0.01) * s;
                    }
                    if (0..3).any(|k| p[k] < dlo[k] || p[k] > dhi[k]) {
                        continue;
                    }
                    if colliders.iter().any(|c| c.distance(p) < 0.0) {
                        continue;
                    }
                    out.pos.push([p[0], p[1], p[2], 0.0]);
                    out.vel.push([vel[0], vel[1], vel[2], 0.0]);
                    out.attr
                        .push([color[0], color[1], color[2], f32::from_bits(group)]);
                }
            }
        }
    }
    out
}
