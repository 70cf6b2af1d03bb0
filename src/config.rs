//! Command-line switches shared by `run` and `bench` (names fixed by DESIGN.md).
//! Values are closed enums so an unknown value is rejected by the parser; a switch whose
//! algorithm is not built yet is rejected by `reject_unimplemented` with a clear message.
use crate::error::{Error, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;

macro_rules! switch_enum {
    ($(#[$m:meta])* $name:ident { $($v:ident),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, ValueEnum, Serialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum $name { $($v),+ }
        impl $name {
            /// The switch value as written on the command line.
            pub fn as_str(self) -> String {
                self.to_possible_value().map(|v| v.get_name().to_string()).unwrap_or_default()
            }
        }
    };
}

switch_enum!(SortAlgo {
    OddEven,
    Bitonic,
    Counting
});
switch_enum!(Neighbors { Morton, Grid, Hash });
switch_enum!(ListKind {
    None,
    Abuffer,
    Sbuffer
});
switch_enum!(DensityFn {
    Blinn,
    Wyvill,
    Nishimura,
    Murakami
});
switch_enum!(Material {
    Phong,
    Glass,
    Tinted,
    Gold,
    Copper,
    Aluminium
});
switch_enum!(Placement {
    Vertices,
    Random,
    Rays
});
switch_enum!(Skinning { Lbs, Dqs });
switch_enum!(OnOff { On, Off });
switch_enum!(BoneWeights { Eq8, Eq9 });

/// Every switch of DESIGN.md's command line. Unset optional switches take the default of
/// whatever uses them; `config` in summary.json records what was used.
#[derive(Args, Clone, Debug, Serialize)]
pub struct Switches {
    /// Device index or name substring (see `fluidform devices`)
    #[arg(long)]
    pub device: Option<String>,
    /// Frame width in pixels
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: u32,
    /// Frame height in pixels
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: u32,
    /// Seed of every random choice (initial particles, test data)
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Khronos validation layer on; the run fails on any validation error
    #[arg(long)]
    pub validation: bool,
    /// Particle count
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=(1 << 26)))]
    pub particles: Option<u32>,
    #[arg(long, value_enum)]
    pub sort: Option<SortAlgo>,
    #[arg(long, value_enum)]
    pub neighbors: Option<Neighbors>,
    #[arg(long, value_enum)]
    pub list: Option<ListKind>,
    #[arg(long, value_enum)]
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
    #[arg(long, value_enum)]
    pub material: Option<Material>,
    #[arg(long, value_enum)]
    pub placement: Option<Placement>,
    #[arg(long, value_enum)]
    pub skinning: Option<Skinning>,
    /// Control pressure c_cp
    #[arg(long)]
    pub control_pressure: Option<f32>,
    #[arg(long, value_enum)]
    pub adaptive: Option<OnOff>,
    #[arg(long, value_enum)]
    pub bone_weights: Option<BoneWeights>,
}

impl Switches {
    /// Fail for every set switch that `supported` does not list, naming the feature that
    /// will bring it: a switch never silently does nothing.
    pub fn reject_unimplemented(&self, what: &str, supported: &[&str]) -> Result<()> {
        let set: [(&str, bool, &str); 14] = [
            ("sort", self.sort.is_some(), "GPU sorts (issue 3)"),
            (
                "neighbors",
                self.neighbors.is_some(),
                "neighbour search (issue 3)",
            ),
            (
                "list",
                self.list.is_some(),
                "the metaball renderer (issue 5)",
            ),
            (
                "density",
                self.density.is_some(),
                "the metaball renderer (issue 5)",
            ),
            (
                "threshold",
                self.threshold.is_some(),
                "the metaball renderer (issue 5)",
            ),
            (
                "radius",
                self.radius.is_some(),
                "the metaball renderer (issue 5)",
            ),
            (
                "refine",
                self.refine.is_some(),
                "the metaball renderer (issue 5)",
            ),
            (
                "depth",
                self.depth.is_some(),
                "the metaball renderer (issue 5)",
            ),
            (
                "material",
                self.material.is_some(),
                "the metaball renderer (issue 5)",
            ),
            ("placement", self.placement.is_some(), "control particles"),
            ("skinning", self.skinning.is_some(), "character skinning"),
            (
                "control-pressure",
                self.control_pressure.is_some(),
                "control particles",
            ),
            ("adaptive", self.adaptive.is_some(), "control particles"),
            (
                "bone-weights",
                self.bone_weights.is_some(),
                "control particles",
            ),
        ];
        for (name, is_set, owner) in set {
            if is_set && !supported.contains(&name) {
                return Err(Error::Unsupported(format!(
                    "--{name} is not implemented yet for {what}: it arrives with {owner}"
                )));
            }
        }
        Ok(())
    }
}
