//! The sized buffers of a surface: the G-buffer and its inputs per pixel, and for marching
//! cubes the density grid over the fluid's bounds, the case table and the triangle soup
//! (grown when a frame overflows it).
use super::{SurfaceFluid, SurfacePush, FILTER_CAP, ISO};
use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context, Guard};
use crate::isosurface::table::{table, EDGES};
use crate::render::SurfaceKind;

pub struct SurfaceBuffers {
    pub(super) zbits: Buffer,
    pub(super) thick: Buffer,
    pub(super) gbuf: Buffer,
    pub(super) smoothed: Buffer,
    pub(super) grid: Buffer,
    pub(super) cases: Buffer,
    pub(super) verts: Buffer,
    pub(super) args: Buffer,
    pub(super) pixels: u64,
    /// The frame's width and height.
    pub(super) size: (u32, u32),
    /// The soup's capacity in vertices.
    pub capacity: u64,
    pub shape: GridShape,
    fluid: SurfaceFluid,
}

/// The marching-cubes grid: origin, cell and nodes per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridShape {
    pub origin: [f32; 3],
    pub cell: f32,
    pub dims: [u32; 3],
}

impl GridShape {
    /// Nodes over `bounds` with a margin of h plus a cell, so the nodes on the grid's
    /// boundary are outside the fluid and the surface is closed.
    pub fn over(fluid: &SurfaceFluid, cell: f32) -> Self {
        let margin = fluid.h + cell;
        let [lo, hi] = fluid.bounds;
        let origin = lo.map(|v| v - margin);
        let dims = [0, 1, 2].map(|k| ((hi[k] + margin - origin[k]) / cell).ceil() as u32 + 1);
        Self { origin, cell, dims }
    }

    pub fn nodes(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    pub fn cells(&self) -> u64 {
        self.dims
            .iter()
            .map(|&d| d.saturating_sub(1) as u64)
            .product()
    }
}

/// Bytes per pixel of a surface's buffers: (all, the largest one).
pub fn pixel_bytes(kind: SurfaceKind) -> (u64, u64) {
    match kind {
        SurfaceKind::Metaballs => (0, 0),
        // zbits, thick, G-buffer (2 vec4), smoothed (2 vec2)
        SurfaceKind::ScreenSpace => (4 + 4 + 32 + 16, 32),
        SurfaceKind::Mesh => (4 + 4 + 32, 32),
    }
}

/// The case table as cells.comp reads it: 257 offsets, 12 edges, the triangles.
fn case_table() -> Vec<u32> {
    let cases = table();
    let mut offsets = vec![0u32];
    let mut tris = Vec::new();
    for c in &cases {
        for t in c {
            tris.push(t[0] as u32 | (t[1] as u32) << 4 | (t[2] as u32) << 8);
        }
        offsets.push(tris.len() as u32);
    }
    let edges = EDGES.iter().map(|&(a, b)| a as u32 | (b as u32) << 4);
    offsets.into_iter().chain(edges).chain(tris).collect()
}

/// Bytes a soup vertex takes (position and normal).
const VERTEX_BYTES: u64 = 32;

impl SurfaceBuffers {
    /// Bytes of its buffers now.
    pub fn bytes(&self) -> u64 {
        let b = [
            &self.zbits,
            &self.thick,
            &self.gbuf,
            &self.smoothed,
            &self.grid,
            &self.cases,
            &self.verts,
            &self.args,
        ];
        b.iter().map(|b| b.size).sum()
    }

    /// Buffers for a `size` frame of `n` particles; `cell` is the marching cubes'
    /// cell in rest spacings.
    pub fn new(
        ctx: &Context,
        kind: SurfaceKind,
        fluid: &SurfaceFluid,
        cell: f32,
        size: (u32, u32),
        n: u64,
    ) -> Result<Self> {
        let pixels = size.0 as u64 * size.1 as u64;
        fluid.validate()?;
        let mesh = kind == SurfaceKind::Mesh;
        let grid = GridShape::over(fluid, cell * fluid.spacing);
        let range = ctx.max_storage_range();
        if mesh && grid.nodes() * 4 > range {
            return Err(Error::Memory(format!(
                "a marching-cubes grid of {:?} nodes ({} MiB) is more than one storage binding \
                 addresses here ({} MiB): use a larger --mesh-cell",
                grid.dims,
                (grid.nodes() * 4) >> 20,
                range >> 20
            )));
        }
        // About 16 triangles per particle on the surface, n^(2/3) of them, per cell^2.
        let guess = (16.0 * (n as f64).powf(2.0 / 3.0) / (cell as f64 * cell as f64)) as u64;
        let capacity = match mesh {
            true => (3 * guess.max(16384)).min(range / VERTEX_BYTES),
            false => 0,
        };
        let only = |used: bool, bytes: u64| if used { bytes } else { 16 };
        let buf =
            |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).map(|b| Guard::new(ctx, b));
        let zbits = buf("surface depth", pixels * 4)?;
        let thick = buf("surface thickness", pixels * 4)?;
        let gbuf = buf("surface g-buffer", pixels * 32)?;
        let smoothed = buf(
            "surface smoothed depth",
            only(kind == SurfaceKind::ScreenSpace, pixels * 16),
        )?;
        let grid_buf = buf("density grid", only(mesh, grid.nodes() * 4))?;
        let table = case_table();
        let mut cases = buf("case table", only(mesh, table.len() as u64 * 4))?;
        let verts = buf("triangle soup", only(mesh, capacity * VERTEX_BYTES))?;
        let args = Guard::new(ctx, ctx.indirect_buffer("surface draw args", 40)?);
        if mesh {
            ctx.upload(&mut cases, 0, &table)?;
        }
        Ok(Self {
            zbits: zbits.take(),
            thick: thick.take(),
            gbuf: gbuf.take(),
            smoothed: smoothed.take(),
            grid: grid_buf.take(),
            cases: cases.take(),
            verts: verts.take(),
            args: args.take(),
            pixels,
            size,
            capacity,
            shape: grid,
            fluid: *fluid,
        })
    }

    /// Room for `triangles` (a frame overflowed), with a quarter to spare.
    pub fn grow(&mut self, ctx: &Context, triangles: u64) -> Result<()> {
        let want = 3 * (triangles + triangles / 4 + 1);
        let fits = ctx.max_storage_range() / VERTEX_BYTES;
        if want > fits {
            return Err(Error::Memory(format!(
                "the surface mesh needs {triangles} triangles, more than one storage binding \
                 addresses here ({}): use a larger --mesh-cell",
                fits / 3
            )));
        }
        let fresh = ctx.storage_buffer("triangle soup", want * VERTEX_BYTES)?;
        ctx.destroy_buffer(&mut self.verts);
        self.verts = fresh;
        self.capacity = want;
        Ok(())
    }

    /// The push constants of every pass.
    pub(super) fn push(&self) -> SurfacePush {
        let f = &self.fluid;
        let g = &self.shape;
        let h = f.h;
        SurfacePush {
            origin: [g.origin[0], g.origin[1], g.origin[2], g.cell],
            dims: [g.dims[0], g.dims[1], g.dims[2], self.capacity as u32],
            fluid: [
                h,
                f.spacing.powi(3),
                315.0 / (64.0 * std::f32::consts::PI * h.powi(9)),
                f.splat_radius(),
            ],
            look: [ISO, 0.0, FILTER_CAP, 0.0],
        }
    }

    /// The density grid of the frame last drawn (marching cubes; tests).
    pub fn density(&self, ctx: &Context) -> Result<Vec<f32>> {
        let raw: Vec<u32> = ctx.readback(&self.grid, 0, self.shape.nodes() as usize)?;
        Ok(raw.iter().map(|&v| v as f32 / super::GRID_SCALE).collect())
    }

    /// The triangle soup of the frame last drawn: (position, normal) per vertex.
    pub fn soup(&self, ctx: &Context) -> Result<Vec<[[f32; 4]; 2]>> {
        let [count]: [u32; 1] = ctx.readback(&self.args, 0, 1)?.try_into().unwrap_or([0]);
        let count = (count as u64).min(self.capacity) as usize;
        ctx.readback(&self.verts, 0, count)
    }

    /// The splats of the frame last drawn, before smoothing (screen-space; tests): per
    /// pixel the nearest view depth (0: none) and the thickness.
    pub fn splats(&self, ctx: &Context) -> Result<(Vec<f32>, Vec<f32>)> {
        let z: Vec<u32> = ctx.readback(&self.zbits, 0, self.pixels as usize)?;
        let t: Vec<i32> = ctx.readback(&self.thick, 0, self.pixels as usize)?;
        Ok((
            z.iter()
                .map(|&b| {
                    if b == u32::MAX {
                        0.0
                    } else {
                        f32::from_bits(b)
                    }
                })
                .collect(),
            t.iter().map(|&v| v as f32 / super::THICK_SCALE).collect(),
        ))
    }

    /// The G-buffer of the frame last drawn: per pixel (view depth, normal), (thickness).
    pub fn gbuffer(&self, ctx: &Context) -> Result<Vec<[[f32; 4]; 2]>> {
        ctx.readback(&self.gbuf, 0, self.pixels as usize)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.zbits,
            &mut self.thick,
            &mut self.gbuf,
            &mut self.smoothed,
            &mut self.grid,
            &mut self.cases,
            &mut self.verts,
            &mut self.args,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(SurfaceBuffers);
