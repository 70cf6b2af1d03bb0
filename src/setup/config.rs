//! Command-line switches shared by `run`, `view` and `bench` (names fixed by DESIGN.md).
//! Only the application sees them: `settings` turns them into the lower crates' settings.
//! Values are closed enums so an unknown value is rejected by the parser; a switch the
//! chosen scene or benchmark does not use is rejected by `reject_unused` with a clear
//! message naming what uses it.
use crate::error::{Error, Result};
use clap::Args;
use serde::Serialize;

use crate::character::Skinning;
use crate::control::{Adaptive, BoneWeights, ControlMotion, ControlPreset, Deficit, Placement};
use crate::emission::EmitterKind;
pub use crate::kinds::Kind;
use crate::kinds::{Neighbors, SortAlgo};
use crate::psys::{Integrator, SpriteMode};
use crate::render::{
    BuildKind, Counters, DensityFn, Lanes, ListKind, MarchKind, Material, Offscreen, RenderKind,
    ShowMesh, SurfaceKind,
};
use crate::sph::{Kernel, Solver};
use clap::builder::TypedValueParser;
use fluidform_gpu::switch_enum;

switch_enum!(
    /// A switch that is on or off.
    OnOff { On, Off }
);

/// The parser of a `Kind` switch: its values listed in --help and in the error for an
/// unknown one.
pub fn choice<K: Kind + Send + Sync>() -> impl clap::builder::TypedValueParser<Value = K> {
    clap::builder::PossibleValuesParser::new(K::ALL.iter().map(|k| k.as_str()))
        .map(|s| s.parse::<K>().expect("a listed value parses"))
}

/// The device, validation, seed and size: every command takes these.
#[derive(Args, Clone, Debug, Serialize, serde::Deserialize)]
pub struct CommonArgs {
    /// Device index or name substring (see `fluidform devices`)
    #[arg(long)]
    pub device: Option<String>,
    /// Khronos validation layer on; the run fails on any validation error
    #[arg(long)]
    pub validation: bool,
    /// No progress bar or progress lines
    #[arg(long)]
    pub quiet: bool,
    /// Seed of every random choice (initial particles, test data)
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Particle count
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=(1 << 26)))]
    pub particles: Option<u32>,
    /// Write the GPU passes of every (timed) frame as Chrome trace JSON to FILE: open it in
    /// Perfetto (ui.perfetto.dev) or chrome://tracing
    #[arg(long, value_name = "FILE")]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trace: Option<std::path::PathBuf>,
    /// Which GPU scopes write timestamps in `run`: frame (the frame alone), passes (the
    /// frame and the scopes directly in it: sph, render, ...) or all (default: every pass)
    #[arg(long, value_parser = choice::<fluidform_gpu::ScopeDepth>())]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scopes: Option<fluidform_gpu::ScopeDepth>,
}

/// Size of rendered frames.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct FrameArgs {
    /// Frame width in pixels (default 512, or the scene's)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: Option<u32>,
    /// Frame height in pixels (default 512, or the scene's)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: Option<u32>,
    /// Samples per pixel of saved pictures (for papers): 1, 4, 9 or 16 on a k x k grid,
    /// rendered k times wider and higher and box-filtered down in linear light
    #[arg(long, value_parser = samples)]
    pub samples: Option<u32>,
}

fn samples(s: &str) -> std::result::Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n @ (1 | 4 | 9 | 16)) => Ok(n),
        _ => Err(format!(
            "{s}: samples per pixel are 1, 4, 9 or 16 (a k x k grid)"
        )),
    }
}

impl FrameArgs {
    pub const DEFAULT: u32 = 512;
    /// The rendered width: the picture's times the sample grid's side.
    pub fn width(&self) -> u32 {
        self.width.unwrap_or(Self::DEFAULT) * self.grid()
    }
    pub fn height(&self) -> u32 {
        self.height.unwrap_or(Self::DEFAULT) * self.grid()
    }
    /// The sample grid's side k (samples = k^2).
    pub fn grid(&self) -> u32 {
        match self.samples.unwrap_or(1) {
            16 => 4,
            9 => 3,
            4 => 2,
            _ => 1,
        }
    }
}

/// The sort of the neighbour search and the sort benchmark.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct SortArgs {
    #[arg(long, value_parser = choice::<SortAlgo>())]
    pub sort: Option<SortAlgo>,
}

/// GPU particle systems (seed 003).
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct ParticleArgs {
    /// Particle-system integrator: euler and verlet keep state on the GPU; closed
    /// evaluates p0 + v0 t + g t^2 / 2 in the vertex shader (gravity only, no update pass)
    #[arg(long, value_parser = choice::<Integrator>())]
    pub integrator: Option<Integrator>,
    /// How particle systems are drawn (default: each system's own)
    #[arg(long, value_parser = choice::<SpriteMode>())]
    pub draw: Option<SpriteMode>,
}

/// Neighbour search strategy.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct NeighborArgs {
    #[arg(long, value_parser = choice::<Neighbors>())]
    pub neighbors: Option<Neighbors>,
}

/// SPH parameters.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct FluidArgs {
    /// Override a fluid parameter of an SPH scene, e.g. --fluid viscosity=1.5
    /// --fluid eos=tait (repeatable; the keys of a scene file's `[fluid]` table)
    #[arg(long = "fluid", value_name = "KEY=VALUE")]
    pub fluid: Vec<String>,
    /// SPH pressure solver (default: the scene's `[fluid]` solver, else wcsph)
    #[arg(long, value_parser = choice::<Solver>())]
    pub solver: Option<Solver>,
    /// SPH smoothing kernel, one for densities and pressure gradients: muller (the
    /// thesis's poly6 with spiky; wcsph's and pbf's default), cubic (pcisph's and dfsph's
    /// default, support 2 spacings) or wendland (3 spacings); --fluid support= changes it
    #[arg(long, value_parser = choice::<Kernel>())]
    pub kernel: Option<Kernel>,
}

impl FluidArgs {
    /// `fluid` with `--fluid KEY=VALUE`, `--kernel` and `--solver` applied.
    pub fn apply(&self, fluid: &crate::sph::FluidParams) -> Result<crate::sph::FluidParams> {
        let mut over = self.fluid.clone();
        over.extend(self.kernel.map(|k| format!("kernel=\"{}\"", k.as_str())));
        fluid.with_overrides(&over, self.solver)
    }
}

/// How `run` draws SPH particles.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct ViewArgs {
    /// How `run` draws particles: ray-marched metaballs (default for SPH scenes) or spheres
    #[arg(long, value_parser = choice::<RenderKind>())]
    pub render: Option<RenderKind>,
}

/// The metaball renderer (seed 000, section 4).
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct MetaballArgs {
    #[arg(long, value_parser = choice::<ListKind>())]
    pub list: Option<ListKind>,
    #[arg(long, value_parser = choice::<DensityFn>())]
    pub density: Option<DensityFn>,
    /// Metaball iso threshold T
    #[arg(long)]
    pub threshold: Option<f32>,
    /// Metaball radius R
    #[arg(long)]
    pub radius: Option<f32>,
    /// Binary-search refinement steps I
    #[arg(long)]
    pub refine: Option<u32>,
    /// Recursion depth D of transparent materials
    #[arg(long)]
    pub depth: Option<u32>,
    #[arg(long, value_parser = choice::<Material>())]
    pub material: Option<Material>,
    /// Equirectangular sky image (PNG, JPEG, ...) instead of the procedural sky
    #[arg(long, value_name = "FILE")]
    pub sky: Option<String>,
    /// Secondary-ray samples off screen: use every metaball (all) or end the path (end)
    #[arg(long, value_parser = choice::<Offscreen>())]
    pub offscreen: Option<Offscreen>,
    /// S-buffer ranges sorted by depth, so each sample reads only the metaballs within R of
    /// its depth (default: on for glass and tinted; off: the thesis's unsorted S-buffer)
    #[arg(long, value_parser = choice::<OnOff>())]
    pub list_sort: Option<OnOff>,
    /// The fluid's surface: ray-marched metaballs (default), screen-space fluid, or a
    /// marching-cubes mesh over the SPH density, all shaded with --material
    #[arg(long, value_parser = choice::<SurfaceKind>())]
    pub surface: Option<SurfaceKind>,
    /// Marching-cubes cell of --surface mesh, in rest particle spacings (default 0.5)
    #[arg(long, value_name = "F")]
    pub mesh_cell: Option<f32>,
    /// The primary rays' march: every sample of the fixed step (the thesis's, default), or
    /// lipschitz: samples the field's Lipschitz bound proves outside are skipped (same hits)
    #[arg(long, value_parser = choice::<MarchKind>())]
    pub march: Option<MarchKind>,
    /// How the march counts rays, samples and terms into 64 slots: per subgroup (default),
    /// summed per workgroup first, or off (no counts: to measure what counting costs)
    #[arg(long, value_parser = choice::<Counters>())]
    pub counters: Option<Counters>,
    /// How the march lays pixels on invocations: 8 x 8 blocks (default) or rows of 64
    #[arg(long, value_parser = choice::<Lanes>())]
    pub lanes: Option<Lanes>,
    /// Lanes that march one ray together: 1 (one invocation per ray, default), 8, 16 or
    /// 32 (each lane a grid sample of the ray: the same hits; at most the subgroup's size)
    #[arg(long, value_name = "N", value_parser = clap::builder::PossibleValuesParser::new(["1", "8", "16", "32"]).map(|s| s.parse::<u32>().expect("listed")))]
    pub ray_lanes: Option<u32>,
    /// Secondary rays pass over the samples in cells of an occupancy grid that no
    /// metaball reaches: on (default; the same hits from fewer samples) or off (every sample)
    #[arg(long, value_parser = choice::<OnOff>())]
    pub occupancy: Option<OnOff>,
    /// How the S-buffer's per-pixel lists are built: rasterising the billboards (the
    /// thesis's, default) or compute from the per-tile lists (already in depth order)
    #[arg(long, value_parser = choice::<BuildKind>())]
    pub build: Option<BuildKind>,
    /// Tile size in pixels of --list tiles and --build compute: 8, 16 (default) or 32
    #[arg(long, value_name = "PX")]
    pub tile: Option<u32>,
}

/// Camera of rendered scenes.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct CameraArgs {
    /// Camera position x,y,z (overrides the scene's)
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3)]
    pub eye: Option<[f32; 3]>,
    /// Camera target x,y,z (overrides the scene's)
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3)]
    pub target: Option<[f32; 3]>,
    /// Vertical field of view in degrees
    #[arg(long, value_parser = parse_fov)]
    pub fov: Option<f32>,
}

switch_enum!(ExportFormat { Ply, Vtk });
switch_enum!(MeshFormat { Obj, Ply });

/// Particle files for ParaView, Blender and splashsurf (SPH runs).
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct ExportArgs {
    /// Write the particles as binary PLY or legacy VTK files, with particles.csv
    #[arg(long, value_parser = choice::<ExportFormat>())]
    pub export: Option<ExportFormat>,
    /// Write the fluid's surface per exported frame as a mesh: marching cubes over the SPH
    /// density (half the particle spacing, iso 0.5 rho_0), OBJ or binary PLY with normals
    #[arg(long, value_parser = choice::<MeshFormat>())]
    pub export_mesh: Option<MeshFormat>,
    /// Export every K-th frame (default 1)
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub export_every: Option<u64>,
}

/// Characters: how they are skinned and drawn.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct CharacterArgs {
    /// Skinning: linear blend (lbs, default) or dual quaternions (dqs, Kavan et al. 2008)
    #[arg(long, value_parser = choice::<Skinning>())]
    pub skinning: Option<Skinning>,
    /// Draw the character's mesh: shaded, as a wireframe, or not at all (default shaded
    /// with no fluid, off with fluid)
    #[arg(long, value_parser = choice::<ShowMesh>())]
    pub show_mesh: Option<ShowMesh>,
}

/// Control particles (scenes with a `[control]` target).
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct ControlArgs {
    /// Control-particle placement: one per welded vertex, Poisson-disk points inside
    /// (closed meshes), or rays: parallel rays through the skinned mesh, re-placed every
    /// frame on the GPU
    #[arg(long, value_parser = choice::<Placement>())]
    pub placement: Option<Placement>,
    /// Control-particle spacing in metres (default: the fluid's rest spacing)
    #[arg(long)]
    pub control_spacing: Option<f32>,
    /// Control pressure c_cp of the driving force (eq. 7)
    #[arg(long)]
    pub control_pressure: Option<f32>,
    /// Control radius h_c in metres (default: twice the fluid's h)
    #[arg(long)]
    pub control_radius: Option<f32>,
    /// Adaptive control pressure: off, on (x2 below 80%, x0.5 above 120% of rho_0), or
    /// smooth (ours: fades from x2 to 0 between 80% and 120%)
    #[arg(long, value_parser = choice::<Adaptive>())]
    pub adaptive: Option<Adaptive>,
    /// Adaptive thresholds as fractions of rho_0 (default 0.8,1.2)
    #[arg(long, value_delimiter = ',', value_name = "LOW,HIGH")]
    pub adaptive_thresholds: Option<Vec<f32>>,
    /// Adaptive factors below LOW and above HIGH (default 2,0.5)
    #[arg(long, value_delimiter = ',', value_name = "UP,DOWN")]
    pub adaptive_factors: Option<Vec<f32>>,
    /// K of a velocity term pulling the fluid to the control particles' velocity (0: off)
    #[arg(long)]
    pub control_velocity: Option<f32>,
    /// Defaults of the control techniques not set otherwise: thesis (eq. 7 alone, as seed
    /// 000) or fidelity (ours: adds the deficit attraction, velocity matching and damping;
    /// the default)
    #[arg(long, value_parser = choice::<ControlPreset>())]
    pub control_preset: Option<ControlPreset>,
    /// Deficit attraction in m/s^2 (after Thuerey et al. 2006): fluid is pulled towards the
    /// control particles within --control-reach still short of rest density (0: off)
    #[arg(long)]
    pub control_attraction: Option<f32>,
    /// Reach of the deficit attraction and the damping in metres (default 5 h_c; the
    /// thesis preset 3 h_c)
    #[arg(long)]
    pub control_reach: Option<f32>,
    /// Damping (1/s) of the fluid's velocity relative to the character's near it, within
    /// the reach (0: off)
    #[arg(long)]
    pub control_damping: Option<f32>,
    /// Velocity of the control particles for the velocity term and the damping: frames
    /// (the last two frames' poses, a frame behind) or skin (the skin's motion over the
    /// frame ahead)
    #[arg(long, value_parser = choice::<ControlMotion>())]
    pub control_motion: Option<ControlMotion>,
    /// What the deficit attraction measures a control particle's deficit against: rest
    /// density (default), or shape (the density fluid filling the shape exactly has there:
    /// about 0.8 at a flat surface; needs --placement random)
    #[arg(long, value_parser = choice::<Deficit>())]
    pub control_deficit: Option<Deficit>,
    /// Steps between refreshes of the control's sums (control densities, eq. 7's walk; the
    /// deficit field follows each pose); the steps between apply each particle's stored
    /// eq. 7 sum with their own density and velocity, and a frame's first step always
    /// refreshes (1: every step, the thesis's preset; fidelity: 1.8 ms over the step,
    /// rounded)
    #[arg(long, value_name = "K")]
    pub control_every: Option<u32>,
    /// Scene time in seconds from which the fidelity metrics are summarised in
    /// summary.json (default: the second half of the run)
    #[arg(long, value_name = "T")]
    pub metrics_from: Option<f64>,
    /// Bone weights of control particles: eq8 (the thesis), eq9 (the thesis's eq. 9 is
    /// lost: normalised inverse squared distance stands in), or skin (the nearest vertex's
    /// skin weights)
    #[arg(long, value_parser = choice::<BoneWeights>())]
    pub bone_weights: Option<BoneWeights>,
}

/// Motion-trail emission (scenes with `[emission]`).
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct EmissionArgs {
    /// Where particles are born: uv (random covered texels of the skinned mesh rendered
    /// into its UV atlas, seed 002) or vertices (random vertices: the baseline)
    #[arg(long, value_parser = choice::<EmitterKind>())]
    pub emitter: Option<EmitterKind>,
    /// Births per second at most (default: every due slot is born, as Algorithm 1)
    #[arg(long)]
    pub emission_rate: Option<f32>,
    /// Life limit in seconds (a birth draws an age in (0, limit/2))
    #[arg(long)]
    pub life_limit: Option<f32>,
    /// Energy transfer rate k of eq. 7, in units of the surface's velocity (1: particles
    /// leave with the surface's own velocity)
    #[arg(long)]
    pub transfer: Option<f32>,
    /// UV atlas size in texels, WxH or N (N x N)
    #[arg(long, value_parser = parse_size)]
    pub uv_size: Option<[u32; 2]>,
}

fn parse_size(s: &str) -> std::result::Result<[u32; 2], String> {
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}' is not WxH or N (positive integers)"))
    };
    let v = match s.split_once(['x', 'X']) {
        Some((w, h)) => [parse(w)?, parse(h)?],
        None => [parse(s)?; 2],
    };
    if v.contains(&0) {
        return Err(format!("'{s}': sizes must be positive"));
    }
    Ok(v)
}

/// Every switch of DESIGN.md's command line, grouped per subsystem. `run` takes all of
/// them (its scene is chosen at run time, so `reject_unused` refuses those a scene
/// does not use); each `bench` takes only its groups, so the parser refuses the others.
/// Unset optional switches take the default of whatever uses them; `config.switches` in
/// summary.json (flat) records what was used.
#[derive(Args, Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct Switches {
    #[command(flatten)]
    #[serde(flatten)]
    pub common: CommonArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub frame: FrameArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub sorting: SortArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub search: NeighborArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub fluid_args: FluidArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub view: ViewArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub metaball: MetaballArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub camera: CameraArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub export: ExportArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub character: CharacterArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub control: ControlArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub emission: EmissionArgs,
    #[command(flatten)]
    #[serde(flatten)]
    pub particle: ParticleArgs,
}

impl Default for CommonArgs {
    /// The parser's defaults.
    fn default() -> Self {
        Self {
            device: None,
            validation: false,
            quiet: false,
            seed: 1,
            particles: None,
            trace: None,
            scopes: None,
        }
    }
}

fn parse_vec3(s: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>().map_err(|e| format!("'{x}': {e}")))
        .collect::<std::result::Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!("expected three finite numbers x,y,z, got '{s}'")),
    }
}

fn parse_fov(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s.parse().map_err(|e| format!("{e}"))?;
    if v > 1.0 && v < 179.0 {
        Ok(v)
    } else {
        Err(format!(
            "field of view must be in (1, 179) degrees, got {v}"
        ))
    }
}

/// A switch group, for `Switches::reject_unused`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    Sort,
    Neighbors,
    Fluid,
    View,
    Metaball,
    Camera,
    Export,
    Character,
    Control,
    Emission,
    Particles,
}

/// The switches of `g` that differ from the group's defaults, as written on the command
/// line (`--list-sort`), found through the group's serialisation: adding a switch to a
/// group needs no list here.
fn set_in<T: Serialize + Default>(g: &T) -> Vec<String> {
    let (now, default) = (serde_json::to_value(g), serde_json::to_value(T::default()));
    let (Ok(serde_json::Value::Object(now)), Ok(serde_json::Value::Object(default))) =
        (now, default)
    else {
        return Vec::new();
    };
    now.iter()
        .filter(|(k, v)| default.get(*k) != Some(*v))
        .map(|(k, _)| format!("--{}", k.replace('_', "-")))
        .collect()
}

impl Switches {
    /// `--scopes` other than `all` belongs to `run`: `what` (a bench, an experiment, the
    /// window) reads every pass's time, so it is refused there in one line.
    pub fn all_scopes(&self, what: &str) -> Result<()> {
        match self.common.scopes {
            Some(s) if s != fluidform_gpu::ScopeDepth::All => Err(Error::Unsupported(format!(
                "--scopes {} belongs to run: {what} times every pass (--scopes all)",
                s.as_str()
            ))),
            _ => Ok(()),
        }
    }

    /// Fail on the first set switch of a group that `what` does not use, naming what uses
    /// it: a switch never silently does nothing. The common and frame groups always apply.
    pub fn reject_unused(&self, what: &str, uses: &[Group]) -> Result<()> {
        let groups: [(Group, Vec<String>, &str); 11] = [
            (
                Group::Sort,
                set_in(&self.sorting),
                "neighbour search and sorts (SPH scenes, bench sort/neighbors/sph/stability)",
            ),
            (
                Group::Neighbors,
                set_in(&self.search),
                "neighbour search (SPH scenes, bench neighbors/sph/stability)",
            ),
            (
                Group::Fluid,
                set_in(&self.fluid_args),
                "SPH parameters (SPH scenes, bench sph/stability)",
            ),
            (Group::View, set_in(&self.view), "run with an SPH scene"),
            (
                Group::Metaball,
                set_in(&self.metaball),
                "the metaball renderer (SPH scenes drawn as metaballs, bench render)",
            ),
            (
                Group::Camera,
                set_in(&self.camera),
                "rendered SPH scenes and bench render",
            ),
            (Group::Export, set_in(&self.export), "run with an SPH scene"),
            (
                Group::Character,
                set_in(&self.character),
                "scenes with a character (run) and bench skin",
            ),
            (
                Group::Control,
                set_in(&self.control),
                "scenes with a [control] target (control particles)",
            ),
            (
                Group::Emission,
                set_in(&self.emission),
                "scenes with [emission] (motion-trail emission) and bench emission",
            ),
            (
                Group::Particles,
                set_in(&self.particle),
                "particle-system scenes (fountain, rain, smoke, flock) and bench particles",
            ),
        ];
        for (g, set, owner) in groups {
            if let Some(name) = set.first().filter(|_| !uses.contains(&g)) {
                return Err(Error::Unsupported(format!(
                    "{name} does not apply to {what}: it is used by {owner}"
                )));
            }
        }
        Ok(())
    }
}
