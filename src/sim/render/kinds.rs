//! The renderers' choices: list modes and builds, density functions, materials, the march's step, counters and lanes, surfaces.
//! Closed sets (`fluidform_gpu::kinds::Kind`): each parses and prints as its switch spells it.
use fluidform_gpu::switch_enum;

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
switch_enum!(
    /// The metaball density functions D(q), q = r / R: the thesis's four (Blinn's
    /// truncated Gaussian, Wyvill, Nishimura, Murakami) and Wendland's C2,
    /// (1 - q)^4 (4q + 1).
    DensityFn {
        Blinn,
        Wyvill,
        Nishimura,
        Murakami,
        Wendland
    }
);
switch_enum!(Material {
    Phong,
    Glass,
    Tinted,
    Gold,
    Copper,
    Aluminium
});
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
switch_enum!(Offscreen { All, End });
switch_enum!(RenderKind { Metaballs, Points });

impl Material {
    /// The shaders' switch on the material's path: MATERIAL and its named values, the
    /// metals sharing one path (MATERIAL_METAL, their indices of refraction set apart).
    pub fn define_path(self) -> Vec<(String, String)> {
        let path = |m: Material| match m {
            Material::Phong => 0u32,
            Material::Glass => 1,
            Material::Tinted => 2,
            Material::Gold | Material::Copper | Material::Aluminium => 3,
        };
        let mut d = vec![("MATERIAL".to_string(), path(self).to_string())];
        let named = [
            ("phong", Material::Phong),
            ("glass", Material::Glass),
            ("tinted", Material::Tinted),
            ("metal", Material::Gold),
        ];
        let refs: Vec<(&str, u32)> = named.iter().map(|(n, m)| (*n, path(*m))).collect();
        d.extend(fluidform_gpu::interface::enum_defines("MATERIAL", &refs));
        d
    }
}
