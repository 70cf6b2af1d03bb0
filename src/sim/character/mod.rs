//! Characters: glTF 2.0 and OBJ loading, mesh checks, clip sampling and orientation,
//! skinning (a GPU pass with linear blend or dual quaternions, and its CPU reference), the
//! thickness of their parts, and what `inspect` reports and draws.
mod kinds;
pub use kinds::Skinning;
pub mod anim;
pub mod capsules;
pub mod check;
pub mod cpu;
mod gltf_clips;
pub mod gltf_files;
pub mod gltf_load;
mod gltf_morphs;
pub mod gltf_quantized;
pub mod inside;
pub mod inspect;
pub mod model;
pub mod obj_load;
pub mod picture;
pub mod pose;
pub mod procedural;
pub mod skin;
pub mod thickness;
pub mod winding;

pub use anim::Animator;
pub use check::MeshCheck;
pub use model::*;

use crate::error::{Error, Result};
use glam::{Mat4, Vec3};
use std::path::Path;

/// A character or mesh file by its extension, or a built-in shape (`builtin:NAME`).
pub fn load(name: &str) -> Result<Character> {
    if let Some(b) = name.strip_prefix("builtin:") {
        return procedural::built_in(b);
    }
    let path = Path::new(name);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "glb" | "gltf" => gltf_load::load(path),
        "obj" => obj_load::load(path),
        _ => Err(Error::Model {
            path: name.to_string(),
            message: format!(
                "unknown mesh format (.glb, .gltf or .obj, or builtin:{})",
                procedural::BUILT_IN.join("|builtin:")
            ),
        }),
    }
}

/// Finish a loaded mesh: normals computed where the file has none, inward-facing closed
/// meshes flipped, the checks at the rest pose.
pub(crate) fn assemble(
    source: String,
    (mut mesh, has_normal): (Mesh, Vec<bool>),
    skeleton: Skeleton,
    clips: Vec<Clip>,
    skinned: bool,
    mut warnings: Vec<String>,
) -> Result<Character> {
    let raw_vertices = mesh.vertices();
    let mut ch = Character {
        source,
        mesh: Mesh::default(),
        skeleton,
        clips,
        skinned,
        raw_vertices,
        normals_computed: false,
        check: MeshCheck::default(),
        flipped: false,
        warnings: Vec::new(),
        parts: Vec::new(),
        capsules: Vec::new(),
    };
    // Normals first (the rest pose skins them too); given ones kept, zero ones replaced.
    let computed = check::area_normals(&mesh.positions, &mesh.indices);
    for (v, n) in mesh.normals.iter_mut().enumerate() {
        let given = has_normal[v] && n.length_squared() > 0.0;
        *n = if given { n.normalize() } else { computed[v] };
    }
    ch.normals_computed = has_normal.iter().any(|h| !h);
    ch.mesh = mesh;
    let rest = ch.rest_positions()?;
    ch.check = check::check(&rest, &ch.mesh.indices);
    if !ch.check.closed() {
        warnings.push(format!(
            "the mesh is open ({}): inside is where its generalized winding number is above 1/2",
            ch.check.describe()
        ));
    }
    // A closed mesh's signed volume says which way it faces; an open one's depends on where
    // its origin is, so its winding number just behind its triangles says instead.
    let (inward, why) = match ch.check.closed() {
        true => (
            ch.check.signed_volume < 0.0,
            format!("signed volume {:.6}", ch.check.signed_volume),
        ),
        false => {
            let (outward, inward) = winding::facing(&rest, &ch.mesh.indices);
            (
                inward > outward,
                format!("its winding number is below -1/2 behind {inward} probed triangles, above 1/2 behind {outward}"),
            )
        }
    };
    if inward {
        check::flip(&mut ch.mesh.indices);
        for n in &mut ch.mesh.normals {
            *n = -*n;
        }
        for d in &mut ch.mesh.morphs.deltas {
            d.normal = -d.normal;
        }
        let closed = if ch.check.closed() { "closed" } else { "open" };
        warnings.push(format!(
            "the {closed} mesh faced inward ({why}); its triangles and normals were flipped"
        ));
        ch.check.signed_volume = -ch.check.signed_volume;
        ch.flipped = true;
    }
    ch.warnings = warnings;
    Ok(ch)
}

impl Character {
    pub fn joint_name(&self, j: usize) -> String {
        self.skeleton.nodes[self.skeleton.joints[j].node]
            .name
            .clone()
    }

    /// Vertex positions skinned with the rest pose (the nodes' own transforms).
    pub fn rest_positions(&self) -> Result<Vec<Vec3>> {
        Ok(self.skinned_at(&self.rest_matrices(), Skinning::Lbs)?.0)
    }

    pub fn rest_matrices(&self) -> Vec<Mat4> {
        let g = self.skeleton.globals(&self.skeleton.rest_locals());
        self.skeleton.joint_matrices(&g)
    }

    /// What the skinning shader reads for joint matrices `mats`.
    pub fn gpu_joints(&self, mats: &[Mat4], method: Skinning) -> Result<Vec<pose::GpuJoint>> {
        pose::gpu_joints(mats, method, &|j| self.joint_name(j))
    }

    /// CPU-skinned positions and normals for joint matrices `mats`, morph targets at
    /// their default weights.
    pub fn skinned_at(&self, mats: &[Mat4], method: Skinning) -> Result<(Vec<Vec3>, Vec<Vec3>)> {
        self.skinned_with(mats, &self.mesh.morphs.defaults(), method)
    }

    /// The same with morph target weights `weights`.
    pub fn skinned_with(
        &self,
        mats: &[Mat4],
        weights: &[f32],
        method: Skinning,
    ) -> Result<(Vec<Vec3>, Vec<Vec3>)> {
        let joints = self.gpu_joints(mats, method)?;
        Ok(cpu::skin(method, &joints, &self.mesh, weights))
    }

    /// The rest pose's bounding box.
    pub fn rest_bounds(&self) -> Result<(Vec3, Vec3)> {
        Ok(check::bounds(&self.rest_positions()?))
    }

    /// A clip by name or index; the error lists the valid ones.
    pub fn clip_index(&self, sel: &str) -> Result<usize> {
        if let Some(i) = self.clips.iter().position(|c| c.name == sel) {
            return Ok(i);
        }
        if let Ok(i) = sel.parse::<usize>() {
            if i < self.clips.len() {
                return Ok(i);
            }
        }
        let names: Vec<String> = self
            .clips
            .iter()
            .enumerate()
            .map(|(i, c)| format!("{i} '{}'", c.name))
            .collect();
        Err(Error::Model {
            path: self.source.clone(),
            message: match names.is_empty() {
                true => format!("has no animation (asked for '{sel}')"),
                false => format!("has no animation '{sel}'; it has: {}", names.join(", ")),
            },
        })
    }

    /// The parts that are open, each with its counts (the whole mesh when the file has no
    /// parts of its own).
    pub fn open_parts(&self) -> Vec<String> {
        if self.parts.is_empty() {
            return match self.check.closed() {
                true => Vec::new(),
                false => vec![format!("the mesh ({})", self.check.describe())],
            };
        }
        (self.parts.iter())
            .filter(|p| !p.closed())
            .map(|p| {
                format!(
                    "'{}' ({} boundary, {} non-manifold edges)",
                    p.node, p.boundary_edges, p.nonmanifold_edges
                )
            })
            .collect()
    }

    /// Refuse a static mesh where a skin is needed.
    pub fn require_skin(&self, why: &str) -> Result<()> {
        match self.skinned {
            true => Ok(()),
            false => Err(Error::Model {
                path: self.source.clone(),
                message: format!("has no skin, which {why} needs"),
            }),
        }
    }

    /// Refuse an open mesh where only a closed one will do, with the counts.
    pub fn require_closed(&self, why: &str) -> Result<()> {
        match self.check.closed() {
            true => Ok(()),
            false => Err(Error::Model {
                path: self.source.clone(),
                message: format!(
                    "is not closed ({}), which {why} needs",
                    self.check.describe()
                ),
            }),
        }
    }

    /// Refuse a mesh with no inside (`rest`: its rest positions): an open one whose
    /// generalized winding number is nowhere above 1/2 (a sheet), probed just behind up to
    /// 512 of its triangles (`winding::facing`): a solid's is about 1 there, a sheet's at
    /// most 1/2.
    pub fn require_solid(&self, rest: &[Vec3]) -> Result<()> {
        if self.check.closed() || winding::facing(rest, &self.mesh.indices).0 > 0 {
            return Ok(());
        }
        Err(Error::Model {
            path: self.source.clone(),
            message: format!(
                "has no inside: its generalized winding number is nowhere above 1/2 (an open sheet, {}), so no fluid can fill it",
                self.check.describe()
            ),
        })
    }
}
