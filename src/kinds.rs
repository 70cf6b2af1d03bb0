//! The closed sets of algorithm and look choices (sorts, neighbour searches, solvers,
//! list modes, materials, ...): plain values every layer may name, below the command line
//! (`config`), which offers them as switches. Each parses and prints as its switch spells it.
macro_rules! switch_enum {
    ($(#[$m:meta])* $name:ident { $($v:ident),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum $name { $($v),+ }
        impl $name {
            /// The switch value as written on the command line.
            pub fn as_str(self) -> String {
                <Self as clap::ValueEnum>::to_possible_value(&self)
                    .map(|v| v.get_name().to_string())
                    .unwrap_or_default()
            }
            /// `PREFIX_NAME` = value for every variant, for a shader's runtime switch.
            pub fn defines(prefix: &str) -> Vec<(String, String)> {
                let names: Vec<(String, u32)> = <Self as clap::ValueEnum>::value_variants()
                    .iter()
                    .map(|v| (v.as_str(), *v as u32))
                    .collect();
                let refs: Vec<(&str, u32)> = names.iter().map(|(n, v)| (n.as_str(), *v)).collect();
                crate::gpu::interface::enum_defines(prefix, &refs)
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
    /// SPH smoothing kernel, one for densities and pressure gradients alike (src/sph/kernel.rs):
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
pub(crate) use switch_enum;
