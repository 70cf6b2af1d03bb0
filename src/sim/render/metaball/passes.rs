//! The metaball renderer's passes as declarations, with the keys they are built with: the
//! list and look every pass compiles with (common.glsl's switches), and the march's own
//! step, counters, lanes and path stack. Each key enumerates the settings that can run it.
use super::renderer::MetaballIo;
use super::settings::{MetaballSettings, MAX_DEPTH, RAY_LANES};
use crate::gpu::pass::{Defines, PassKey};
use crate::render::{Counters, DensityFn, Lanes, ListKind, MarchKind, Material};

/// The list and look: LIST, DENSITY (with its Lipschitz slope), MATERIAL and SORTED.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ListKey {
    pub list: ListKind,
    pub density: DensityFn,
    pub material: Material,
    /// A sorted S-buffer (only the S-buffer has an unsorted and a sorted form).
    pub sorted: bool,
}

impl ListKey {
    pub fn of(s: &MetaballSettings) -> Self {
        Self {
            list: s.list,
            density: s.density,
            material: s.material,
            sorted: s.sorts_lists(),
        }
    }

    /// Every list (the S-buffer unsorted and sorted) with every density and material.
    fn every() -> Vec<Self> {
        let mut v = Vec::new();
        for list in ListKind::all() {
            let sorts: &[bool] = match list {
                ListKind::Sbuffer => &[false, true],
                _ => &[false],
            };
            for sorted in sorts {
                for density in DensityFn::all() {
                    for material in Material::all() {
                        v.push(Self {
                            list: *list,
                            density: *density,
                            material: *material,
                            sorted: *sorted,
                        });
                    }
                }
            }
        }
        v
    }

    fn list_defines(&self) -> Defines {
        MetaballSettings::defines_for(self.list, self.density, self.material, self.sorted)
    }
}

/// Which lists a pass runs for (the `U` of [`Lists`]).
pub mod uses {
    /// The raster-built S-buffer's count and fill.
    pub const RASTER_SBUFFER: u8 = 0;
    /// The A-buffer's fill.
    pub const ABUFFER: u8 = 1;
    /// The raster-built sorted S-buffer's depth sort.
    pub const SORTED_SBUFFER: u8 = 2;
    /// The per-tile lists: tiles, and the S-buffer built from them in compute.
    pub const TILED: u8 = 3;
    /// The compute-built S-buffer's per-pixel ranges.
    pub const SBUFFER: u8 = 4;
}

/// A list-and-look key restricted to the lists a pass runs for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lists<const U: u8>(pub ListKey);

impl<const U: u8> PassKey for Lists<U> {
    fn all() -> Vec<Self> {
        let runs = |k: &ListKey| match U {
            uses::RASTER_SBUFFER | uses::SBUFFER => k.list == ListKind::Sbuffer,
            uses::ABUFFER => k.list == ListKind::Abuffer,
            uses::SORTED_SBUFFER => k.list == ListKind::Sbuffer && k.sorted,
            uses::TILED => matches!(k.list, ListKind::Tiles | ListKind::Sbuffer),
            _ => false,
        };
        ListKey::every()
            .into_iter()
            .filter(runs)
            .map(Self)
            .collect()
    }
    fn defines(&self) -> Defines {
        self.0.list_defines()
    }
}

/// The march's variant: the list and look, the step, counters, lanes, lanes per ray and
/// path stack.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MarchKey {
    pub lists: ListKey,
    pub march: MarchKind,
    pub counters: Counters,
    pub lanes: Lanes,
    pub ray_lanes: u32,
    pub depth: u32,
}

impl MarchKey {
    pub fn of(s: &MetaballSettings) -> Self {
        Self {
            lists: ListKey::of(s),
            march: s.march,
            counters: s.counters,
            lanes: s.lanes,
            ray_lanes: s.ray_lanes,
            depth: s.depth,
        }
    }

    /// The lane layouts a list marches with (tiles march 8 x 8 blocks only).
    fn lanes(list: ListKind) -> &'static [Lanes] {
        match list {
            ListKind::Tiles => &[Lanes::Blocks],
            _ => Lanes::all(),
        }
    }
}

impl PassKey for MarchKey {
    fn all() -> Vec<Self> {
        let mut v = Vec::new();
        for lists in ListKey::every() {
            for march in MarchKind::all() {
                for counters in Counters::all() {
                    for lanes in Self::lanes(lists.list) {
                        for ray_lanes in RAY_LANES {
                            for depth in 0..=MAX_DEPTH {
                                v.push(Self {
                                    lists,
                                    march: *march,
                                    counters: *counters,
                                    lanes: *lanes,
                                    ray_lanes,
                                    depth,
                                });
                            }
                        }
                    }
                }
            }
        }
        v
    }

    fn defines(&self) -> Defines {
        let mut d = self.lists.list_defines();
        d.extend(MetaballSettings::march_defines(self.march));
        d.extend(MetaballSettings::lane_defines(
            self.counters,
            self.lanes,
            self.ray_lanes,
        ));
        d.extend(MetaballSettings::stack_defines(self.depth));
        d
    }

    /// Every list, look and step at the default counters, lanes and depth; every counter
    /// mode and lane layout on the default look (their code reads no look); every depth
    /// on glass over the S-buffer (the stack's code reads no list); every lanes per ray on
    /// every list, with Phong's both steps and glass's path. Every line of march.comp
    /// compiles, and the whole product (about 56000 variants) is not rebuilt.
    fn compiled() -> Vec<Self> {
        let d = MarchKey::of(&MetaballSettings::thesis());
        Self::all()
            .into_iter()
            .filter(|k| {
                let plain = k.lists.density == DensityFn::Wyvill
                    && k.lists.material == Material::Phong
                    && k.march == MarchKind::Fixed;
                let glass = k.lists.density == DensityFn::Wyvill
                    && k.lists.material == Material::Glass
                    && k.lists.list == ListKind::Sbuffer
                    && k.march == MarchKind::Fixed;
                let laned = k.ray_lanes != d.ray_lanes
                    && k.lists.density == DensityFn::Wyvill
                    && (k.lists.material == Material::Phong
                        || (k.lists.material == Material::Glass && k.march == MarchKind::Fixed));
                let usual = (k.counters, k.lanes) == (d.counters, d.lanes);
                let serial = k.ray_lanes == d.ray_lanes;
                (serial && (usual || plain) && k.depth == d.depth)
                    || (serial && glass && usual)
                    || (laned && usual && k.depth == d.depth)
            })
            .collect()
    }
}

/// The occupancy grid's build reads the radius and bounds, never the density; common.glsl's
/// functions need one to compile, so it compiles with Wyvill's: one variant for every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OccupancyKey;

impl PassKey for OccupancyKey {
    fn all() -> Vec<Self> {
        vec![OccupancyKey]
    }
    fn defines(&self) -> Defines {
        DensityFn::Wyvill.define("DENSITY")
    }
}

use uses::*;
crate::gpu::graphics_pass!(
    /// Counts each pixel's metaballs (the S-buffer's first raster pass).
    pub COUNT: MetaballIo, Lists<RASTER_SBUFFER> = "count",
    "render/metaball/billboard.vert", "render/metaball/billboard.frag", "PASS" = "0"
);
crate::gpu::graphics_pass!(
    /// Writes each pixel's metaballs into its S-buffer range.
    pub FILL: MetaballIo, Lists<RASTER_SBUFFER> = "fill",
    "render/metaball/billboard.vert", "render/metaball/billboard.frag", "PASS" = "1"
);
crate::gpu::graphics_pass!(
    /// Links each pixel's metaballs into its A-buffer list.
    pub ABUFFER_FILL: MetaballIo, Lists<ABUFFER> = "fill",
    "render/metaball/billboard.vert", "render/metaball/billboard.frag", "PASS" = "2"
);
crate::gpu::compute_pass!(pub DEPTHS: MetaballIo, Lists<SORTED_SBUFFER> = "depths", "render/metaball/depths.comp");
crate::gpu::compute_pass!(pub SORT_LISTS: MetaballIo, Lists<SORTED_SBUFFER> = "sort lists", "render/metaball/sort_lists.comp");
crate::gpu::compute_pass!(pub MARCH: MetaballIo, MarchKey = "march", "render/metaball/march.comp");
crate::gpu::compute_pass!(
    /// Marks the cells of the occupancy grid that a metaball reaches (--occupancy on).
    pub OCCUPANCY: MetaballIo, OccupancyKey = "occupancy", "render/metaball/occupancy.comp"
);
crate::gpu::compute_pass!(pub TILE_BIN: MetaballIo, Lists<TILED> = "tile bin", "render/metaball/tile_bin.comp");
crate::gpu::compute_pass!(
    pub TILE_COUNT: MetaballIo, Lists<TILED> = "tile count", "render/metaball/tile_pairs.comp", "PASS" = "0"
);
crate::gpu::compute_pass!(
    pub TILE_EMIT: MetaballIo, Lists<TILED> = "tile emit", "render/metaball/tile_pairs.comp", "PASS" = "1"
);
crate::gpu::compute_pass!(pub TILE_RANGES: MetaballIo, Lists<TILED> = "tile ranges", "render/metaball/tile_ranges.comp");
crate::gpu::compute_pass!(
    pub PIXEL_COUNT: MetaballIo, Lists<SBUFFER> = "pixel count", "render/metaball/pixel_lists.comp", "PASS" = "0"
);
crate::gpu::compute_pass!(
    pub PIXEL_FILL: MetaballIo, Lists<SBUFFER> = "pixel fill", "render/metaball/pixel_lists.comp", "PASS" = "1"
);
