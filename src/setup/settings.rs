//! The switches turned into the lower crates' own settings, at the application's edge:
//! the simulation crate takes `MetaballSettings` and `ControlDesc`, never `Switches`.
use crate::character::Skinning;
use crate::config::Switches;
use crate::control::target::ControlDesc;
use crate::error::{Error, Result};
use crate::render::metaball::MetaballSettings;
use crate::render::ShowMesh;
use crate::render::{BuildKind, ListKind, Material, SurfaceKind};
use crate::scene::emission::EmissionOverrides;
use crate::scene::schema::Look;

/// The metaball settings: the thesis's (`MetaballSettings::thesis`), overridden by the
/// switches that are set.
pub fn metaball_settings(sw: &Switches) -> Result<MetaballSettings> {
    let t = MetaballSettings::thesis();
    let m = &sw.metaball;
    let radius = m.radius.unwrap_or(t.radius);
    let mut s = MetaballSettings {
        list: m.list.unwrap_or(t.list),
        density: m.density.unwrap_or(t.density),
        material: m.material.unwrap_or(t.material),
        threshold: m.threshold.unwrap_or(t.threshold),
        radius,
        refine: m.refine.unwrap_or(t.refine),
        depth: m.depth.unwrap_or(t.depth),
        step: radius / 8.0,
        march: m.march.unwrap_or(t.march),
        counters: m.counters.unwrap_or(t.counters),
        lanes: m.lanes.unwrap_or(t.lanes),
        ray_lanes: m.ray_lanes.unwrap_or(t.ray_lanes),
        occupancy: m
            .occupancy
            .map(|o| o == crate::config::OnOff::On)
            .unwrap_or(t.occupancy),
        build: m.build.unwrap_or(t.build),
        tile: m.tile.unwrap_or(t.tile),
        offscreen_end: m
            .offscreen
            .map(|o| o == crate::render::Offscreen::End)
            .unwrap_or(t.offscreen_end),
        // Sorting pays where rays read the lists many times: inside glass and tinted.
        sorted: match m.list_sort {
            Some(o) => o == crate::config::OnOff::On,
            None => matches!(m.material, Some(Material::Glass) | Some(Material::Tinted)),
        },
        width: sw.frame.width(),
        height: sw.frame.height(),
        sky: m.sky.clone(),
        surface: m.surface.unwrap_or(t.surface),
        mesh_cell: m.mesh_cell.unwrap_or(t.mesh_cell),
        ..t
    };
    if s.surface != SurfaceKind::Metaballs {
        let m = &sw.metaball;
        let listed = [
            ("--list", m.list.is_some()),
            ("--density", m.density.is_some()),
            ("--threshold", m.threshold.is_some()),
            ("--refine", m.refine.is_some()),
            ("--offscreen", m.offscreen.is_some()),
            ("--list-sort", m.list_sort.is_some()),
            ("--march", m.march.is_some()),
            ("--counters", m.counters.is_some()),
            ("--lanes", m.lanes.is_some()),
            ("--ray-lanes", m.ray_lanes.is_some()),
            ("--occupancy", m.occupancy.is_some()),
            ("--build", m.build.is_some()),
            ("--tile", m.tile.is_some()),
        ];
        if let Some((name, _)) = listed.iter().find(|(_, set)| *set) {
            return Err(Error::Param(format!(
                "{name} belongs to the metaball surface, not --surface {}",
                s.surface.as_str()
            )));
        }
        // Nothing is listed or marched.
        s.list = ListKind::None;
        s.sorted = false;
    } else if sw.metaball.mesh_cell.is_some() {
        return Err(Error::Param("--mesh-cell belongs to --surface mesh".into()));
    }
    // Tiles are built in compute; an explicit --build raster is refused by `validate`.
    if s.list == ListKind::Tiles && sw.metaball.build.is_none() {
        s.build = BuildKind::Compute;
    }
    if sw.metaball.tile.is_some() && s.build != BuildKind::Compute {
        return Err(Error::Param(format!(
            "--tile sets the tiles of --list tiles and --build compute, not --list {} \
             built by raster",
            s.list.as_str()
        )));
    }
    if sw.metaball.list_sort.is_some() && s.list != ListKind::Sbuffer {
        return Err(Error::Param(format!(
            "--list-sort applies to the S-buffer's contiguous ranges, not --list {}",
            s.list.as_str()
        )));
    }
    s.validate()?;
    Ok(s)
}

/// `run`'s (and the window's) metaball settings for `n` metaballs: the switches', except
/// that where neither `--build` nor `--list-sort` is given, the S-buffer is built in compute
/// and sorted by depth, its fastest form on every device measured (H200 Phong thesis frame
/// 0.86 ms against the thesis's raster build's 12.6; lavapipe 601 against 813 ms sorted):
/// each pixel holds the same metaballs and the pictures agree (tests/lists.rs). Bench and experiment keep the thesis's build. A frame whose tile pair
/// keys would not fit 32 bits keeps the raster build, and says so in one line.
pub fn run_metaball_settings(sw: &Switches, n: u32) -> Result<MetaballSettings> {
    let mut s = metaball_settings(sw)?;
    let m = &sw.metaball;
    let open = m.build.is_none() && m.list_sort.is_none();
    if !(open && s.list == ListKind::Sbuffer && s.marches()) {
        return Ok(s);
    }
    let fast = MetaballSettings {
        build: BuildKind::Compute,
        sorted: true,
        ..s.clone()
    };
    match crate::render::metaball::settings::check_pair_keys(&fast, n) {
        Ok(()) => s = fast,
        Err(e) if !sw.common.quiet => {
            eprintln!("the S-buffer is built by raster, not in compute as run's default: {e}")
        }
        Err(_) => {}
    }
    Ok(s)
}

/// `desc` with the control switches applied.
fn control_with_switches(desc: &ControlDesc, sw: &Switches) -> Result<ControlDesc> {
    let c = &sw.control;
    let thresholds = pair("--adaptive-thresholds", &c.adaptive_thresholds)?;
    let factors = pair("--adaptive-factors", &c.adaptive_factors)?;
    Ok(ControlDesc {
        placement: c.placement.unwrap_or(desc.placement),
        spacing: c.control_spacing.or(desc.spacing),
        bone_weights: c.bone_weights.unwrap_or(desc.bone_weights),
        pressure: c.control_pressure.unwrap_or(desc.pressure),
        radius: c.control_radius.or(desc.radius),
        adaptive: c.adaptive.unwrap_or(desc.adaptive),
        thresholds: thresholds.unwrap_or(desc.thresholds),
        factors: factors.unwrap_or(desc.factors),
        velocity: c.control_velocity.or(desc.velocity),
        preset: c.control_preset.or(desc.preset),
        attraction: c.control_attraction.or(desc.attraction),
        reach: c.control_reach.or(desc.reach),
        damping: c.control_damping.or(desc.damping),
        motion: c.control_motion.or(desc.motion),
        deficit: c.control_deficit.or(desc.deficit),
        group: desc.group,
        every: c.control_every.or(desc.every),
    })
}

/// The two values of switch `name`, if given.
fn pair(name: &str, v: &Option<Vec<f32>>) -> Result<Option<[f32; 2]>> {
    match v.as_deref() {
        None => Ok(None),
        Some([a, b]) => Ok(Some([*a, *b])),
        Some(v) => Err(Error::Param(format!(
            "{name} takes two numbers separated by a comma, got {}",
            v.len()
        ))),
    }
}

/// A control target's settings: the run's over the scene's (`settings::control_overrides`).
pub type ControlOverrides = Box<dyn Fn(&ControlDesc) -> Result<ControlDesc>>;

/// What the scene's characters and targets take from the run (`settings::target_options`).
pub struct TargetOptions {
    pub skinning: Skinning,
    /// The characters' meshes; None: hidden under control, else shaded.
    pub show_mesh: Option<ShowMesh>,
    pub quiet: bool,
    /// Scene time from which the fidelity metrics are summarised.
    pub metrics_from: Option<f64>,
    pub seed: u64,
    pub emission: EmissionOverrides,
    pub control: ControlOverrides,
}

/// The control switches over a target's own settings, for every target of the run.
pub fn control_overrides(sw: &Switches) -> ControlOverrides {
    let sw = sw.clone();
    Box::new(move |d| control_with_switches(d, &sw))
}

/// What the scene's characters, targets and emission take from the switches.
pub fn target_options(sw: &Switches) -> TargetOptions {
    let e = &sw.emission;
    TargetOptions {
        skinning: sw
            .character
            .skinning
            .unwrap_or(crate::character::Skinning::Lbs),
        show_mesh: sw.character.show_mesh,
        quiet: sw.common.quiet,
        metrics_from: sw.control.metrics_from,
        seed: sw.common.seed,
        emission: EmissionOverrides {
            emitter: e.emitter,
            life_limit: e.life_limit,
            rate: e.emission_rate,
            transfer: e.transfer,
            uv_size: e.uv_size,
        },
        control: control_overrides(sw),
    }
}

/// `sw` with the scene's `[look]` where the switches leave it unset.
pub fn with_look(look: &Look, sw: &Switches) -> Switches {
    let mut sw = sw.clone();
    if sw.metaball.material.is_none() {
        sw.metaball.material = look.material;
    }
    if sw.metaball.surface.is_none()
        && sw.view.render.or(look.render) != Some(crate::render::RenderKind::Points)
    {
        sw.metaball.surface = look.surface;
    }
    if let Some([w, h]) = look.size {
        sw.frame.width = sw.frame.width.or(Some(w));
        sw.frame.height = sw.frame.height.or(Some(h));
    }
    sw
}
