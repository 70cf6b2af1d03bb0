//! Renderer settings from the command line (or a bench configuration), with the thesis's
//! defaults, and their GPU mirror.
use crate::error::{Error, Result};
use crate::render::surface::SurfaceFluid;
use crate::render::Camera;
use crate::render::{
    BuildKind, Counters, DensityFn, Lanes, ListKind, MarchKind, Material, SurfaceKind,
};
use bytemuck::{Pod, Zeroable};
use serde::Serialize;

#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct MetaballSettings {
    pub list: ListKind,
    pub density: DensityFn,
    pub material: Material,
    /// Iso threshold T of the summed density.
    pub threshold: f32,
    /// Metaball support radius R.
    pub radius: f32,
    /// Bisection steps I on a hit.
    pub refine: u32,
    /// Recursion depth D of glass, tinted and metals.
    pub depth: u32,
    /// March step (default R / 8).
    pub step: f32,
    pub max_steps: u32,
    /// The primary rays' march: the fixed grid, or skipping what the Lipschitz bound proves.
    #[serde(default = "thesis_march")]
    pub march: MarchKind,
    /// How the march counts rays, samples and terms (off: no counts, to measure their cost).
    #[serde(default = "thesis_counters")]
    pub counters: Counters,
    /// How the march lays pixels on invocations.
    #[serde(default = "thesis_lanes")]
    pub lanes: Lanes,
    /// Lanes that march one ray together (1: one invocation per ray; `RAY_LANES`).
    #[serde(default = "thesis_ray_lanes")]
    pub ray_lanes: u32,
    /// Secondary rays pass over the samples in cells of an occupancy grid no metaball
    /// reaches (glsl/render/metaball/occupancy.glsl): the same hits from fewer samples.
    #[serde(default = "thesis_occupancy")]
    pub occupancy: bool,
    /// How the S-buffer's lists are built: rasterised billboards, or compute from the
    /// per-tile lists (each range then in depth order, no sort pass). Tiles: compute.
    #[serde(default = "thesis_build")]
    pub build: BuildKind,
    /// Tile size in pixels of the per-tile lists (tiles, and compute-built S-buffers).
    #[serde(default = "thesis_tile")]
    pub tile: u32,
    /// Secondary samples that leave the screen end the path (else: every metaball).
    pub offscreen_end: bool,
    /// S-buffer ranges sorted by the metaballs' view depth (a `sort` pass), each sample
    /// summing only those within R of its depth. Ignored by the other lists. Default: on
    /// for glass and tinted, off for Phong and the metals (one outward bounce).
    pub sorted: bool,
    pub width: u32,
    pub height: u32,
    /// Index of refraction of glass and tinted (water).
    pub ior: f32,
    /// Tinted: absorption per unit length, per channel.
    pub absorb: [f32; 3],
    /// Phong colour ("tar monster").
    pub base: [f32; 3],
    /// The container to draw around the fluid (min, max), as glass walls with dark edges.
    #[serde(default)]
    pub tank: Option<[[f32; 3]; 2]>,
    /// Equirectangular sky image (else the procedural sky).
    pub sky: Option<String>,
    /// An opaque layer (a character's mesh: colour and depth per pixel) is drawn into the
    /// frame; primary rays stop at it and show it where no fluid is in front.
    #[serde(default)]
    pub opaque: bool,
    /// The surface drawn: the metaballs, or screen-space fluid or a marching-cubes mesh
    /// (which need `fluid`), shaded with the same materials.
    #[serde(default = "thesis_surface")]
    pub surface: SurfaceKind,
    /// Marching-cubes cell in rest spacings (`--surface mesh`).
    #[serde(default = "thesis_mesh_cell")]
    pub mesh_cell: f32,
    /// The particles' fluid, for the other surfaces (set by the caller).
    #[serde(default)]
    pub fluid: Option<SurfaceFluid>,
}

impl MetaballSettings {
    /// The thesis's renderer: Wyvill's density at T = 0.9, R = 0.04, march step R / 8 (at
    /// most 2048), I = 2 bisection steps, Phong, the S-buffer built by raster and unsorted,
    /// recursion depth 1 for the materials that branch, 512 x 512; water's index of
    /// refraction and tint. What every switch left unset gives (`settings::metaball_settings`).
    pub fn thesis() -> Self {
        let radius = 0.04;
        Self {
            list: ListKind::Sbuffer,
            density: DensityFn::Wyvill,
            material: Material::Phong,
            threshold: 0.9,
            radius,
            refine: 2,
            depth: 1,
            step: radius / 8.0,
            max_steps: 2048,
            march: MarchKind::Fixed,
            counters: Counters::Subgroup,
            lanes: Lanes::Blocks,
            ray_lanes: 1,
            occupancy: true,
            build: BuildKind::Raster,
            tile: 16,
            offscreen_end: false,
            sorted: false,
            width: 512,
            height: 512,
            ior: 1.33,
            absorb: [6.0, 2.0, 0.8],
            base: [0.08, 0.06, 0.05],
            tank: None,
            sky: None,
            opaque: false,
            surface: SurfaceKind::Metaballs,
            mesh_cell: 0.5,
            fluid: None,
        }
    }
}

// serde's defaults for fields summaries written before them lack: the thesis's.
fn thesis_surface() -> SurfaceKind {
    MetaballSettings::thesis().surface
}

fn thesis_mesh_cell() -> f32 {
    MetaballSettings::thesis().mesh_cell
}

fn thesis_march() -> MarchKind {
    MetaballSettings::thesis().march
}

fn thesis_counters() -> Counters {
    MetaballSettings::thesis().counters
}

fn thesis_lanes() -> Lanes {
    MetaballSettings::thesis().lanes
}

fn thesis_ray_lanes() -> u32 {
    MetaballSettings::thesis().ray_lanes
}

fn thesis_occupancy() -> bool {
    MetaballSettings::thesis().occupancy
}

fn thesis_build() -> BuildKind {
    MetaballSettings::thesis().build
}

fn thesis_tile() -> u32 {
    MetaballSettings::thesis().tile
}

/// The tile sizes `--tile` takes.
pub const TILES: [u32; 3] = [8, 16, 32];

pub const MAX_DEPTH: u32 = 6;
/// The lanes `--ray-lanes` takes (march_lanes.glsl).
pub const RAY_LANES: [u32; 4] = [1, 8, 16, 32];

/// The lanes per ray a device marches with: 1 always, and each wider count its subgroup
/// holds where it has ballots and shuffles (a ray's lanes share one subgroup).
pub fn ray_lanes_on(info: &crate::gpu::DeviceInfo) -> Vec<u32> {
    RAY_LANES
        .into_iter()
        .filter(|&n| n == 1 || (info.subgroup_shuffle && n <= info.subgroup_size))
        .collect()
}
pub const MAX_REFINE: u32 = 32;

/// Complex index of refraction (n, k) per RGB channel (about 650, 550, 450 nm).
pub fn metal_nk(m: Material) -> Option<([f32; 3], [f32; 3])> {
    match m {
        Material::Gold => Some(([0.143, 0.374, 1.442], [3.983, 2.385, 1.603])),
        Material::Copper => Some(([0.200, 0.924, 1.102], [3.912, 2.452, 2.142])),
        Material::Aluminium => Some(([1.657, 0.880, 0.521], [9.224, 6.270, 4.837])),
        _ => None,
    }
}

/// Reflectance at normal incidence from a complex index: ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
pub fn f0_from_nk(n: f32, k: f32) -> f32 {
    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
}

impl MetaballSettings {
    /// Whether the frame sorts its lists (an S-buffer with `sorted`).
    pub fn sorts_lists(&self) -> bool {
        self.sorted && self.list == ListKind::Sbuffer && self.marches()
    }

    /// Whether the frame runs the per-pixel sort pass (sorted lists built by raster; the
    /// compute build fills each range in depth order).
    pub fn sort_pass(&self) -> bool {
        self.sorts_lists() && self.build == BuildKind::Raster
    }

    /// Whether the frame bins the metaballs into per-tile lists (tiles, compute builds).
    pub fn bins_tiles(&self) -> bool {
        self.marches() && self.build == BuildKind::Compute
    }

    /// Whether the march sends secondary rays (glass, tinted and the metals at depth >= 1).
    /// Material and depth are shader defines, so a renderer keeps this through `retune`.
    pub fn has_secondary_rays(&self) -> bool {
        self.marches() && self.material != Material::Phong && self.depth > 0
    }

    /// Whether the frame builds the occupancy grid: secondary rays skip its empty cells.
    pub fn skips_empty(&self) -> bool {
        self.occupancy && self.has_secondary_rays()
    }

    /// Whether the surface is the ray-marched metaballs (the lists are built).
    pub fn marches(&self) -> bool {
        self.surface == SurfaceKind::Metaballs
    }

    /// The list's name in tables: none, abuffer, sbuffer (the thesis's), sbuffer-sorted.
    pub fn list_name(&self) -> String {
        let compute = self.build == BuildKind::Compute;
        let tile = match self.tile {
            16 => String::new(),
            t => format!("-{t}"),
        };
        match self.list {
            ListKind::Sbuffer if self.sorted && compute => format!("sbuffer-sorted-compute{tile}"),
            ListKind::Sbuffer if self.sorted => "sbuffer-sorted".into(),
            ListKind::Sbuffer if compute => format!("sbuffer-compute{tile}"),
            ListKind::Tiles => format!("tiles{tile}"),
            l => l.as_str(),
        }
    }

    pub fn validate(&self) -> Result<()> {
        // Positive, and far from float's ends: the march squares it and takes 1 / R^2.
        if !(self.radius >= 1e-6 && self.radius <= 1e6) {
            return Err(Error::Param(format!(
                "--radius must be positive, from 1e-6 to 1e6 m, got {}",
                self.radius
            )));
        }
        if !(self.threshold > 0.0 && self.threshold.is_finite()) {
            return Err(Error::Param(format!(
                "--threshold must be positive, got {}",
                self.threshold
            )));
        }
        if self.refine > MAX_REFINE {
            return Err(Error::Param(format!(
                "--refine must be at most {MAX_REFINE}, got {}",
                self.refine
            )));
        }
        if !(self.mesh_cell >= 0.1 && self.mesh_cell <= 4.0) {
            return Err(Error::Param(format!(
                "--mesh-cell must be within [0.1, 4] rest spacings, got {}",
                self.mesh_cell
            )));
        }
        if !TILES.contains(&self.tile) {
            return Err(Error::Param(format!(
                "--tile must be 8, 16 or 32 pixels, got {}",
                self.tile
            )));
        }
        match (self.list, self.build) {
            (ListKind::Tiles, BuildKind::Raster) => {
                return Err(Error::Param(
                    "--list tiles is built in compute (its pairs are sorted by tile and \
                     depth); --build raster applies to the S-buffer"
                        .into(),
                ))
            }
            (ListKind::None | ListKind::Abuffer, BuildKind::Compute) => {
                return Err(Error::Param(format!(
                    "--build compute builds the S-buffer's ranges (and the tiles), not --list {}",
                    self.list.as_str()
                )))
            }
            _ => {}
        }
        if (self.list, self.lanes) == (ListKind::Tiles, Lanes::Rows) {
            return Err(Error::Param(
                "--list tiles marches 8 x 8 blocks (its tile is staged per block): not --lanes rows"
                    .into(),
            ));
        }
        if !RAY_LANES.contains(&self.ray_lanes) {
            return Err(Error::Param(format!(
                "--ray-lanes must be 1, 8, 16 or 32, got {}",
                self.ray_lanes
            )));
        }
        if self.depth > MAX_DEPTH {
            return Err(Error::Param(format!(
                "--depth must be at most {MAX_DEPTH}, got {}",
                self.depth
            )));
        }
        Ok(())
    }

    pub fn f0(&self) -> [f32; 3] {
        match metal_nk(self.material) {
            Some((n, k)) => [
                f0_from_nk(n[0], k[0]),
                f0_from_nk(n[1], k[1]),
                f0_from_nk(n[2], k[2]),
            ],
            None => [0.04; 3],
        }
    }

    /// Every define the frame's shaders can read: its march's (the lists', the look's, the
    /// step's, the counters', the lanes' and the stack's; `passes::MarchKey`).
    pub fn shader_defines(&self) -> Vec<(String, String)> {
        use crate::gpu::pass::PassKey;
        super::passes::MarchKey::of(self).defines()
    }

    /// march.comp's path stack for recursion depth `depth`: STACK, its slots (depth + 1,
    /// the most a depth-first walk of glass and tinted holds).
    pub fn stack_defines(depth: u32) -> Vec<(String, String)> {
        vec![("STACK".to_string(), (depth + 1).to_string())]
    }

    /// The march.comp defines of its counters, lane layout and lanes per ray (COUNTERS,
    /// LANES and their named values, RAY_LANES).
    pub fn lane_defines(counters: Counters, lanes: Lanes, ray_lanes: u32) -> Vec<(String, String)> {
        let mut d = counters.define("COUNTERS");
        d.extend(lanes.define("LANES"));
        d.push(("RAY_LANES".to_string(), ray_lanes.to_string()));
        d
    }

    /// The march.comp defines of a march kind (MARCH and its named values).
    pub fn march_defines(march: MarchKind) -> Vec<(String, String)> {
        march.define("MARCH")
    }

    /// The defines of one configuration (also the shader registry's variants).
    pub fn defines_for(
        list: ListKind,
        density: DensityFn,
        material: Material,
        sorted: bool,
    ) -> Vec<(String, String)> {
        let mut d = list.define("LIST");
        d.extend(density.define("DENSITY"));
        d.extend(material.define_path());
        d.push((
            "SORTED".to_string(),
            ((sorted && list == ListKind::Sbuffer) as u32).to_string(),
        ));
        // max |dD/dq| of the density: the march's Lipschitz bound (density.rs).
        d.push((
            "SLOPE_MAX".to_string(),
            format!("{:.6}", density.slope_max()),
        ));
        d
    }

    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

/// Mirror of `RenderParams` in glsl/render/metaball/common.glsl (std430).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct RenderParams {
    pub view_proj: [[f32; 4]; 4],
    pub inv_view_proj: [[f32; 4]; 4],
    pub view: [[f32; 4]; 4],
    pub proj: [f32; 4],
    pub eye: [f32; 4],
    pub sun: [f32; 4],
    pub absorb: [f32; 4],
    pub f0: [f32; 4],
    pub base: [f32; 4],
    /// The container drawn as glass walls with dark edges: min xyz (w = 1: draw), max xyz.
    pub tank_min: [f32; 4],
    pub tank_max: [f32; 4],
    pub width: u32,
    pub height: u32,
    pub n: u32,
    pub refine: u32,
    pub depth: u32,
    pub max_steps: u32,
    pub list_capacity: u32,
    pub offscreen_end: u32,
    pub sky_w: u32,
    pub sky_h: u32,
    pub debug: u32,
    /// 1: the opaque layer (colours, then depths) is bound and used.
    pub opaque: u32,
    /// Per-tile lists: the tile size in pixels, tiles per row, the bits of a pair key's
    /// depth rank (key = tile << rank_bits | rank) and the pairs' capacity.
    pub tile: u32,
    pub tiles_x: u32,
    pub rank_bits: u32,
    pub pair_capacity: u32,
    /// 1: secondary rays pass over the occupancy grid's empty cells.
    pub occupancy: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}
const _: () = assert!(std::mem::size_of::<RenderParams>() == 400);

/// Bits of a pair key's depth rank among `n` metaballs (at least one).
pub fn rank_bits(n: u32) -> u32 {
    (32 - n.saturating_sub(1).leading_zeros()).max(1)
}

/// Tiles of a frame: (per row, in all).
pub fn tile_grid(s: &MetaballSettings) -> (u32, u64) {
    let (tx, ty) = (s.width.div_ceil(s.tile), s.height.div_ceil(s.tile));
    (tx, tx as u64 * ty as u64)
}

/// A pair key (tile << rank_bits | rank) must stay below u32::MAX, the padding's key.
pub fn check_pair_keys(s: &MetaballSettings, n: u32) -> Result<()> {
    let (_, tiles) = tile_grid(s);
    let bits = rank_bits(n);
    if tiles << bits >= u32::MAX as u64 {
        return Err(Error::Param(format!(
            "{tiles} tiles of {} px x {n} metaballs need pair keys of more than 32 bits; use a \
             larger --tile or a smaller frame",
            s.tile
        )));
    }
    Ok(())
}

impl RenderParams {
    pub fn new(
        s: &MetaballSettings,
        cam: &Camera,
        n: u32,
        list_capacity: u64,
        sky: (u32, u32),
        debug: bool,
        pairs: u64,
    ) -> Self {
        let vp = cam.view_proj();
        let proj = cam.proj();
        let sun = glam::Vec3::new(0.4, 0.8, 0.3).normalize();
        let f0 = s.f0();
        Self {
            view_proj: vp.to_cols_array_2d(),
            inv_view_proj: vp.inverse().to_cols_array_2d(),
            view: cam.view().to_cols_array_2d(),
            proj: [proj.x_axis.x, proj.y_axis.y, cam.near, 0.0],
            eye: [cam.eye.x, cam.eye.y, cam.eye.z, s.radius],
            sun: [sun.x, sun.y, sun.z, s.step],
            absorb: [s.absorb[0], s.absorb[1], s.absorb[2], s.ior],
            f0: [f0[0], f0[1], f0[2], 0.0],
            base: [s.base[0], s.base[1], s.base[2], s.threshold],
            tank_min: match s.tank {
                Some([lo, _]) => [lo[0], lo[1], lo[2], 1.0],
                None => [0.0; 4],
            },
            tank_max: match s.tank {
                Some([_, hi]) => [hi[0], hi[1], hi[2], 0.0],
                None => [0.0; 4],
            },
            width: s.width,
            height: s.height,
            n,
            refine: s.refine,
            depth: s.depth,
            max_steps: s.max_steps,
            list_capacity: list_capacity.min(u32::MAX as u64) as u32,
            offscreen_end: s.offscreen_end as u32,
            sky_w: sky.0,
            sky_h: sky.1,
            debug: debug as u32,
            opaque: s.opaque as u32,
            tile: s.tile,
            tiles_x: s.width.div_ceil(s.tile),
            rank_bits: rank_bits(n),
            pair_capacity: pairs.min(u32::MAX as u64) as u32,
            occupancy: s.skips_empty() as u32,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        }
    }
}
