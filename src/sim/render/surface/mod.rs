//! The surfaces researchers compare the metaballs with, drawn with the same materials:
//! screen-space fluid (van der Laan, Green & Sainz 2009: depth splats, bilateral
//! smoothing, normals from depth, thickness; `screen`) and a marching-cubes mesh over the
//! SPH density (`cubes`, checked against `crate::isosurface::march`). Both write one G-buffer
//! (depth, normal, thickness per pixel) that the shade pass lights as the metaballs' march
//! does its first hit, into the metaball renderer's pixels.
pub mod buffers;
pub mod cubes;
pub mod screen;

pub use buffers::SurfaceBuffers;

use crate::error::{Error, Result};
use crate::gpu::pass::{Defines, PassKey};
use crate::gpu::Open;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard, Scopes};
use crate::render::Material;
use crate::render::SurfaceKind;
use bytemuck::{Pod, Zeroable};
use serde::{Deserialize, Serialize};

crate::gpu_interface! {
    /// glsl/render/surface/common.glsl: every surface pass declares all of these.
    pub SurfaceIo / SurfaceBufs: "SF", push SurfacePush {
        params = 0, centers = 1, stats = 2, pixels = 3, sky = 4, opaque = 5, scene_depth = 6,
        zbits = 7, thick = 8, gbuf = 9, smoothed = 10, grid = 11, cases = 12, verts = 13,
        args = 14,
    }
}

/// Mirror of `Push` in glsl/render/surface/common.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SurfacePush {
    /// Marching-cubes grid origin, w = cell.
    pub origin: [f32; 4],
    /// Grid nodes per axis, w = the soup's vertex capacity.
    pub dims: [u32; 4],
    /// Smoothing length h, particle volume m / rho0, poly6 constant, splat radius.
    pub fluid: [f32; 4],
    /// Iso level, smoothing axis (0: x, 1: y), filter half-width cap in pixels.
    pub look: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<SurfacePush>() == 64);

/// What the other surfaces need of the particles' fluid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFluid {
    /// Rest spacing (m): a particle's volume is its cube.
    pub spacing: f32,
    /// SPH smoothing length h (m): the support of the marching cubes' density.
    pub h: f32,
    /// The box the particles stay in (the domain): the marching-cubes grid covers it.
    pub bounds: [[f32; 3]; 2],
}

pub use crate::isosurface::ISO;

/// Fixed point of the density grid (atomic adds of the density over the rest density).
pub const GRID_SCALE: f32 = 4194304.0;
/// Fixed point of the thickness (per metre).
pub const THICK_SCALE: f32 = 65536.0;

/// The defines every surface shader takes: the fixed-point scales.
pub fn scale_defines() -> Vec<(&'static str, String)> {
    vec![
        ("GRID_SCALE", format!("{GRID_SCALE:.1}")),
        ("THICK_SCALE", format!("{THICK_SCALE:.1}")),
    ]
}

/// The screen-space filter's half-width cap in pixels.
pub const FILTER_CAP: f32 = 16.0;

impl SurfaceFluid {
    /// The splat radius: the sphere of a particle's own volume (so splats overlap a little
    /// on the rest lattice, and the thickness needs no rescaling at rest).
    pub fn splat_radius(&self) -> f32 {
        self.spacing * (3.0 / (4.0 * std::f32::consts::PI)).cbrt()
    }

    pub fn validate(&self) -> Result<()> {
        let [lo, hi] = self.bounds;
        let ok = self.spacing > 0.0
            && self.h > 0.0
            && (0..3).all(|k| lo[k].is_finite() && hi[k].is_finite() && hi[k] > lo[k]);
        match ok {
            true => Ok(()),
            false => Err(Error::Param(format!(
                "a surface's fluid is malformed: {self:?}"
            ))),
        }
    }
}

type Compute = ComputePipeline<SurfaceIo>;

/// The surfaces' passes' key: one variant, the fixed-point scales defined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scales;

impl PassKey for Scales {
    fn all() -> Vec<Self> {
        vec![Self]
    }
    fn defines(&self) -> Defines {
        let d = scale_defines().into_iter();
        d.map(|(k, v)| (k.to_string(), v)).collect()
    }
}

/// The surface shading's variant: the material (its path; the metals share one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadeKey(pub Material);

impl PassKey for ShadeKey {
    fn all() -> Vec<Self> {
        Material::all().iter().map(|m| Self(*m)).collect()
    }
    fn defines(&self) -> Defines {
        let mut d = self.0.define_path();
        d.extend(Scales.defines());
        d
    }
}

crate::gpu::compute_pass!(pub SHADE: SurfaceIo, ShadeKey = "shade", "render/surface/shade.comp");

/// What every pass of a frame's surface records with: its buffers, push constants and the
/// particle count.
pub(super) struct Rec<'a> {
    bufs: SurfaceBufs<'a>,
    push: SurfacePush,
    b: &'a SurfaceBuffers,
    n: u32,
}

/// The buffers of the metaball renderer a surface reads and writes (parameters, counters,
/// picture, sky, opaque layer, scene depth) and the frame's particles.
pub struct Frame<'a> {
    pub params: &'a Buffer,
    pub centers: &'a Buffer,
    pub stats: &'a Buffer,
    pub pixels: &'a Buffer,
    pub sky: &'a Buffer,
    pub opaque: &'a Buffer,
    pub scene_depth: &'a Buffer,
}

impl<'a> Frame<'a> {
    fn bufs(&self, b: &'a SurfaceBuffers) -> SurfaceBufs<'a> {
        SurfaceBufs {
            params: self.params,
            centers: self.centers,
            stats: self.stats,
            pixels: self.pixels,
            sky: self.sky,
            opaque: self.opaque,
            scene_depth: self.scene_depth,
            zbits: &b.zbits,
            thick: &b.thick,
            gbuf: &b.gbuf,
            smoothed: &b.smoothed,
            grid: &b.grid,
            cases: &b.cases,
            verts: &b.verts,
            args: &b.args,
        }
    }
}

/// The passes of screen-space fluid or marching cubes, and the shade pass.
pub struct Surface {
    pub kind: SurfaceKind,
    screen: Option<screen::ScreenSpace>,
    cubes: Option<cubes::Cubes>,
    shade: Compute,
}

impl Surface {
    /// `material`: the look it shades with.
    pub fn new(ctx: &Context, kind: SurfaceKind, material: Material) -> Result<Self> {
        let shade = Guard::new(ctx, SHADE.pipeline(ctx, &ShadeKey(material), 64, &[])?);
        let (screen, cubes) = match kind {
            SurfaceKind::ScreenSpace => (Some(screen::ScreenSpace::new(ctx)?), None),
            SurfaceKind::Mesh => (None, Some(cubes::Cubes::new(ctx)?)),
            SurfaceKind::Metaballs => {
                return Err(Error::Param(
                    "the metaballs are the metaball renderer's own surface".into(),
                ))
            }
        };
        Ok(Self {
            kind,
            screen,
            cubes,
            shade: shade.take(),
        })
    }

    /// Record the frame's surface into the G-buffer and shade it into `f.pixels` (the
    /// parameters written and the counters cleared by the caller).
    pub fn record(
        &self,
        ctx: &Context,
        cmd: crate::gpu::vk::CommandBuffer,
        scopes: &mut dyn Scopes,
        f: &Frame,
        b: &SurfaceBuffers,
        n: u32,
    ) -> Result<()> {
        let r = Rec {
            bufs: f.bufs(b),
            push: b.push(),
            b,
            n,
        };
        if let Some(s) = &self.screen {
            s.record(ctx, cmd, scopes, &r);
        }
        if let Some(c) = &self.cubes {
            c.record(ctx, cmd, scopes, &r)?;
        }
        {
            let _scope = scopes.open(ctx, cmd, SHADE.scope());
            self.shade.dispatch(ctx, cmd, &r.bufs, &r.push, b.pixels);
        }
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        if let Some(s) = &mut self.screen {
            s.destroy(ctx);
        }
        if let Some(c) = &mut self.cubes {
            c.destroy(ctx);
        }
        self.shade.destroy(ctx);
    }
}
crate::impl_destroy!(Surface);
