//! The closed sets of algorithm and look choices (sorts, neighbour searches, solvers,
//! list modes, materials, ...): plain values every layer may name, below the command line
//! (the application's `config`), which offers them as switches. Each parses and prints as its switch spells it.
/// A closed set of choices: every value, and each one's name as its switch spells it
/// (kebab case). The command line offers them through `Kind`, so no layer below it needs
/// the command-line parser.
pub trait Kind: Copy + Eq + std::str::FromStr<Err = String> + 'static {
    /// Every value, in declaration order (their shader indices).
    const ALL: &'static [Self];
    /// The name as written on the command line and in scene files.
    fn as_str(self) -> String;
}

/// `OddEven` -> `odd-even`, `Eq8` -> `eq8`: the switch spelling of a variant's name.
pub fn kebab(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                out.push('-');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

/// Declare a `Kind`: the enum, its switch names, parsing with an error that lists them,
/// and `defines` for a shader's runtime switch.
#[macro_export]
macro_rules! switch_enum {
    ($(#[$m:meta])* $name:ident { $($v:ident),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum $name { $($v),+ }
        impl $crate::kinds::Kind for $name {
            const ALL: &'static [Self] = &[$(Self::$v),+];
            fn as_str(self) -> String {
                match self { $(Self::$v => $crate::kinds::kebab(stringify!($v))),+ }
            }
        }
        impl $name {
            /// The switch value as written on the command line.
            pub fn as_str(self) -> String {
                <Self as $crate::kinds::Kind>::as_str(self)
            }
            /// Every value, in declaration order.
            pub fn all() -> &'static [Self] {
                <Self as $crate::kinds::Kind>::ALL
            }
            /// `PREFIX_NAME` = value for every variant, for a shader's runtime switch.
            pub fn defines(prefix: &str) -> Vec<(String, String)> {
                let names: Vec<(String, u32)> = Self::all()
                    .iter()
                    .map(|v| (v.as_str(), *v as u32))
                    .collect();
                let refs: Vec<(&str, u32)> = names.iter().map(|(n, v)| (n.as_str(), *v)).collect();
                $crate::interface::enum_defines(prefix, &refs)
            }
        }
        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                Self::all().iter().copied().find(|v| v.as_str() == s).ok_or_else(|| {
                    let names: Vec<String> = Self::all().iter().map(|v| v.as_str()).collect();
                    format!("'{s}' is none of {}", names.join(", "))
                })
            }
        }
        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(&self.as_str())
            }
        }
    };
}

switch_enum!(SortAlgo {
    OddEven,
    Bitonic,
    Counting,
    None
});
switch_enum!(Integrator {
    Euler,
    Verlet,
    Closed
});
switch_enum!(SpriteMode {
    Points,
    Streaks,
    Sprites
});
switch_enum!(Neighbors { Morton, Grid, Hash });
switch_enum!(
    /// SPH pressure solver: weakly compressible (the papers'), or the incompressible
    /// predictive-corrective, divergence-free and position-based ones.
    Solver {
        Wcsph,
        Pcisph,
        Dfsph,
        Pbf
    }
);

switch_enum!(
    /// SPH smoothing kernel, one for densities and pressure gradients alike (src/sim/sph/kernel.rs):
    /// Mueller 2003's poly6 densities with spiky gradients (the thesis's), the cubic
    /// spline, or Wendland's C2.
    Kernel {
        Muller,
        Cubic,
        Wendland
    }
);

switch_enum!(
    /// The metaball lists: none, the A-buffer's linked lists, the S-buffer's ranges (the
    /// thesis's), or per-tile ranges sorted by (tile, depth) after tile-based splatting.
    ListKind {
        None,
        Abuffer,
        Sbuffer,
        Tiles
    }
);
switch_enum!(
    /// How per-pixel lists are built: by rasterising the billboards (the thesis's), or in
    /// compute from the per-tile lists, each pixel's range already in depth order.
    BuildKind {
        Raster,
        Compute
    }
);
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
switch_enum!(EmitterKind { Uv, Vertices });
switch_enum!(Placement {
    Vertices,
    Random,
    Rays
});
switch_enum!(Skinning { Lbs, Dqs });
switch_enum!(OnOff { On, Off });
switch_enum!(Adaptive { Off, On, Smooth });
switch_enum!(ControlPreset { Thesis, Fidelity });
switch_enum!(ControlMotion { Frames, Skin });
switch_enum!(Deficit { Rest, Shape });
switch_enum!(BoneWeights { Eq8, Eq9, Skin });
switch_enum!(Offscreen { All, End });
switch_enum!(RenderKind { Metaballs, Points });
switch_enum!(
    /// The fluid's surface under `--render metaballs`: the ray-marched metaballs, screen-space
    /// fluid (depth splats, bilateral smoothing, normals from depth) or a marching-cubes mesh.
    SurfaceKind {
        Metaballs,
        ScreenSpace,
        Mesh
    }
);
switch_enum!(ShowMesh { Off, Shaded, Wire });
switch_enum!(
    /// The metaball march's step: the thesis's fixed grid, or the same grid with the samples
    /// skipped that the summed field's Lipschitz bound proves on the ray's side.
    MarchKind {
        Fixed,
        Lipschitz
    }
);

switch_enum!(
    /// How the march counts its rays, samples, terms and candidates (the frame's
    /// statistics), into 64 slots a workgroup picks by its index: added per subgroup, summed
    /// per workgroup first (two barriers) and added once per workgroup, or not at all (to
    /// measure what counting costs; the frame then reports no counts).
    Counters {
        Subgroup,
        Workgroup,
        Off
    }
);

switch_enum!(
    /// How the march lays pixels on a workgroup's 64 invocations: 8 x 8 blocks (neighbouring
    /// rays diverge together at silhouettes and read neighbouring lists) or rows of 64.
    Lanes {
        Blocks,
        Rows
    }
);
