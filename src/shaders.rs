//! Every shader with the defines the code compiles it with: its interface's bindings and
//! each set of feature defines a pass uses. One registration line per pass; the shader
//! test compiles every entry and fails on a GLSL file registered nowhere.
use crate::gpu::Interface;
use crate::kinds::{Neighbors, SortAlgo};
use crate::render::metaball::MetaballSettings;
use crate::render::{Counters, DensityFn, Lanes, ListKind, Material};

/// (file under glsl/, defines).
pub type Variant = (&'static str, Vec<(String, String)>);

fn with<I: Interface>(file: &'static str, extra: &[(String, String)]) -> Variant {
    let mut d = I::defines();
    d.extend(extra.iter().cloned());
    (file, d)
}

fn kv(k: &str, v: impl ToString) -> (String, String) {
    (k.to_string(), v.to_string())
}

pub fn variants() -> Vec<Variant> {
    use crate::primitives::{bounds, counting, morton, scan, sort};
    let mut v = vec![
        with::<bounds::BoundsIo>("primitives/bounds.comp", &[]),
        with::<morton::MortonIo>("primitives/morton.comp", &[]),
        with::<counting::CountIo>("primitives/count.comp", &[]),
        with::<counting::ScatterIo>("primitives/scatter.comp", &[]),
        with::<counting::OrderIo>("primitives/cell_order.comp", &[]),
        with::<counting::GatherIo>("primitives/gather.comp", &[]),
        with::<sort::SortIo>("primitives/oddeven.comp", &[]),
        with::<sort::SortIo>("primitives/bitonic.comp", &[]),
        with::<crate::sph::store::LiveArgsIo>("common/live_args.comp", &[]),
        with::<crate::bench::floor::FmaIo>("bench/fma.comp", &[]),
        with::<crate::sph::hooks::ConstantForceIo>("sph/constant_force.comp", &[]),
        with::<crate::sph::health::HealthIo>("sph/health.comp", &[]),
        with::<crate::sph::errors::StepErrorIo>("sph/step_error.comp", &[]),
        with::<crate::sph::cfl::CflIo>("sph/cfl.comp", &[]),
        with::<crate::scene::orbits::OrbitsIo>("scene/orbits.comp", &[]),
        with::<crate::render::points::PointsIo>("render/points.vert", &[]),
        with::<crate::render::points::PointsIo>("render/points.frag", &[]),
        with::<crate::render::mesh::MeshIo>("render/mesh.vert", &[]),
        with::<crate::render::mesh::MeshIo>("render/mesh.frag", &[]),
    ];
    particle_systems(&mut v);
    use crate::character::skin::{SkinIo, SkinPass};
    for method in [
        crate::character::Skinning::Lbs,
        crate::character::Skinning::Dqs,
    ] {
        for sets in [1, 2] {
            let d: Vec<(String, String)> = SkinPass::defines(method, sets)
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect();
            v.push(with::<SkinIo>("character/skin.comp", &d));
        }
    }
    for sub in [false, true] {
        let d: Vec<(String, String)> = scan::ScanPass::defines(sub)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        for file in [
            "primitives/scan_chunk_down.comp",
            "primitives/scan_block.comp",
        ] {
            v.push(with::<scan::ScanIo>(file, &d));
        }
        for top in ["0", "1"] {
            let mut d = d.clone();
            d.push(("TOP".into(), top.into()));
            v.push(with::<scan::ScanIo>(
                "primitives/scan_chunk_reduce.comp",
                &d,
            ));
        }
    }
    searches_sph_and_control(&mut v);
    v.push(with::<crate::emission::emit::EmitIo>(
        "emission/emit.comp",
        &[],
    ));
    use crate::emission::uv::UvIo;
    for f in [
        "emission/uv.vert",
        "emission/uv.frag",
        "emission/uv_flags.comp",
        "emission/uv_compact.comp",
    ] {
        v.push(with::<UvIo>(f, &[]));
    }
    use crate::control::rays::RaysIo;
    for f in ["control/rays_count.comp", "control/rays_emit.comp"] {
        v.push(with::<RaysIo>(f, &[]));
    }
    for pass in 0..2 {
        let d = [kv("PASS", pass)];
        v.push(with::<RaysIo>("control/rays.vert", &d));
        v.push(with::<RaysIo>("control/rays.frag", &d));
    }
    metaballs(&mut v);
    surfaces(&mut v);
    v
}

/// Particle systems: emit, update (with and without subgroups), boids, the draws.
fn particle_systems(v: &mut Vec<Variant>) {
    use crate::psys::gpu::{DrawIo, PsysIo};
    for f in ["psys/emit.comp", "psys/args.comp", "psys/keys.comp"] {
        v.push(with::<PsysIo>(f, &[]));
    }
    for sub in [false, true] {
        let d: Vec<(String, String)> = crate::psys::Passes::update_defines(sub)
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        v.push(with::<PsysIo>("psys/update.comp", &d));
    }
    let grid = crate::primitives::neighbors::NeighborSearch::defines_for(
        Neighbors::Grid,
        SortAlgo::Counting,
    );
    let grid: Vec<(String, String)> = grid.into_iter().map(|(k, v)| (k.to_string(), v)).collect();
    v.push(with::<crate::psys::gpu::BoidsIo>("psys/boids.comp", &grid));
    for mode in 0..3 {
        for f in ["psys/draw.vert", "psys/draw.frag"] {
            v.push(with::<DrawIo>(f, &[kv("MODE", mode)]));
        }
    }
}

/// Per neighbour search and sort: the search passes, SPH, every pressure solver's passes and the control passes per adaptive mode.
fn searches_sph_and_control(v: &mut Vec<Variant>) {
    use crate::primitives::neighbors;
    for nb in [Neighbors::Grid, Neighbors::Hash, Neighbors::Morton] {
        for sort in [SortAlgo::Counting, SortAlgo::OddEven, SortAlgo::Bitonic] {
            let d: Vec<(String, String)> = neighbors::NeighborSearch::defines_for(nb, sort)
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect();
            // The Morton search makes its keys in its own pass.
            if nb != Neighbors::Morton {
                v.push(with::<neighbors::NbKeysIo>("primitives/nb_keys.comp", &d));
            }
            v.push(with::<neighbors::NbRangesIo>(
                "primitives/nb_ranges.comp",
                &d,
            ));
            v.push(with::<neighbors::NbQueryIo>("primitives/nb_query.comp", &d));
            let mut sph = d.clone();
            sph.extend(crate::sph::params::defines());
            sph.extend(crate::sph::pressure::solver_defines());
            for f in ["sph/density.comp", "sph/forces.comp", "sph/integrate.comp"] {
                v.push(with::<crate::sph::solver::SphIo>(f, &sph));
            }
            use crate::sph::pressure::{pass_defines, passes, PressureIo};
            use crate::sph::Solver;
            for solver in Solver::all() {
                for p in passes(*solver) {
                    let mut d = sph.clone();
                    d.extend(pass_defines(&p));
                    v.push(with::<PressureIo>(p.shader, &d));
                }
            }
            use crate::control::force::{ControlIo, ControlSettings};
            for a in crate::control::Adaptive::all() {
                let mut c = sph.clone();
                c.extend(
                    ControlSettings::defines(*a)
                        .into_iter()
                        .map(|(k, v)| (k.to_string(), v)),
                );
                for f in [
                    "control/density.comp",
                    "control/aggregate.comp",
                    "control/field.comp",
                ] {
                    v.push(with::<ControlIo>(f, &c));
                }
                for refresh in ["0", "1"] {
                    let mut d = c.clone();
                    d.push(kv("CONTROL_REFRESH", refresh));
                    v.push(with::<ControlIo>("control/force.comp", &d));
                }
            }
        }
    }
}

/// The metaball renderer per list, material, density function and sort; the tile passes.
fn metaballs(v: &mut Vec<Variant>) {
    use crate::render::metaball::renderer::MetaballIo;
    let lists = [
        ListKind::None,
        ListKind::Abuffer,
        ListKind::Sbuffer,
        ListKind::Tiles,
    ];
    for list in lists {
        for material in [
            Material::Phong,
            Material::Glass,
            Material::Tinted,
            Material::Gold,
        ] {
            for density in DensityFn::all() {
                // Only the S-buffer has an unsorted and a sorted form.
                for sorted in [false, true] {
                    if sorted && list != ListKind::Sbuffer {
                        continue;
                    }
                    let d = MetaballSettings::defines_for(list, *density, material, sorted);
                    for march in crate::render::MarchKind::all() {
                        let mut d = d.clone();
                        d.extend(MetaballSettings::march_defines(*march));
                        // Counters and lanes per list on the default look only: they
                        // change nothing the look's code reads.
                        let plain = material == Material::Phong
                            && *density == DensityFn::Wyvill
                            && *march == crate::render::MarchKind::Fixed;
                        for (counters, lanes) in lane_variants(list, plain) {
                            let mut d = d.clone();
                            d.extend(MetaballSettings::lane_defines(counters, lanes));
                            // Every stack size (depth 0..=6) on one list and look; the
                            // default depth's elsewhere.
                            let deep = material == Material::Glass
                                && *density == DensityFn::Wyvill
                                && *march == crate::render::MarchKind::Fixed
                                && list == ListKind::Sbuffer
                                && (counters, lanes) == (Counters::Subgroup, Lanes::Blocks);
                            let depths = if deep { 0..=6 } else { 1..=1 };
                            for depth in depths {
                                let mut d = d.clone();
                                d.extend(MetaballSettings::stack_defines(depth));
                                v.push(with::<MetaballIo>("render/metaball/march.comp", &d));
                            }
                        }
                    }
                    if list == ListKind::Tiles {
                        continue;
                    }
                    for f in [
                        "render/metaball/depths.comp",
                        "render/metaball/sort_lists.comp",
                    ] {
                        v.push(with::<MetaballIo>(f, &d));
                    }
                    for pass in 0..3 {
                        let mut d = d.clone();
                        d.push(kv("PASS", pass));
                        v.push(with::<MetaballIo>("render/metaball/billboard.vert", &d));
                        v.push(with::<MetaballIo>("render/metaball/billboard.frag", &d));
                    }
                }
            }
        }
    }
    // The tile passes read no material or density.
    let d =
        MetaballSettings::defines_for(ListKind::Tiles, DensityFn::Wyvill, Material::Phong, false);
    v.push(with::<MetaballIo>("render/metaball/tile_bin.comp", &d));
    v.push(with::<MetaballIo>("render/metaball/tile_ranges.comp", &d));
    for pass in 0..2 {
        let mut d = d.clone();
        d.push(kv("PASS", pass));
        v.push(with::<MetaballIo>("render/metaball/tile_pairs.comp", &d));
        v.push(with::<MetaballIo>("render/metaball/pixel_lists.comp", &d));
    }
}

/// The march's counter modes and lane layouts to compile: every pair that can run where
/// `all`, else the defaults' (tiles march blocks only).
fn lane_variants(list: ListKind, all: bool) -> Vec<(Counters, Lanes)> {
    let lanes: &[Lanes] = match list {
        ListKind::Tiles => &[Lanes::Blocks],
        _ => Lanes::all(),
    };
    match all {
        true => Counters::all()
            .iter()
            .flat_map(|c| lanes.iter().map(move |l| (*c, *l)))
            .collect(),
        false => vec![(Counters::Subgroup, Lanes::Blocks)],
    }
}

/// Screen-space fluid and marching cubes: their passes, and the shade pass per material.
fn surfaces(v: &mut Vec<Variant>) {
    use crate::render::surface::{scale_defines, SurfaceIo};
    let scales: Vec<(String, String)> = (scale_defines().into_iter())
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    for f in [
        "render/surface/splat.vert",
        "render/surface/splat.frag",
        "render/surface/smooth.comp",
        "render/surface/normals.comp",
        "render/surface/density.comp",
        "render/surface/cells.comp",
    ] {
        v.push(with::<SurfaceIo>(f, &scales));
    }
    for pass in 0..2 {
        let mut d = scales.clone();
        d.push(kv("PASS", pass));
        v.push(with::<SurfaceIo>("render/surface/mesh.vert", &d));
        v.push(with::<SurfaceIo>("render/surface/mesh.frag", &d));
    }
    for material in [
        Material::Phong,
        Material::Glass,
        Material::Tinted,
        Material::Gold,
    ] {
        let mut d =
            MetaballSettings::defines_for(ListKind::None, DensityFn::Wyvill, material, false);
        d.extend(scales.iter().cloned());
        v.push(with::<SurfaceIo>("render/surface/shade.comp", &d));
    }
}
