//! OBJ (through tobj, triangulated): a static mesh, one joint.
use super::model::*;
use crate::error::{Error, Result};
use glam::{Vec2, Vec3};
use std::path::Path;

pub fn load(path: &Path) -> Result<Character> {
    std::fs::metadata(path).map_err(|e| Error::Io {
        path: path.display().to_string(),
        source: e,
    })?;
    let bad = |message: String| Error::Model {
        path: path.display().to_string(),
        message,
    };
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    // Materials are not needed: a missing .mtl must not fail the mesh.
    let (models, _) =
        tobj::load_obj(path, &opts).map_err(|e| bad(format!("not a readable OBJ file: {e}")))?;
    let mut m = Mesh {
        influence_sets: 1,
        ..Default::default()
    };
    let mut has_normal = Vec::new();
    let any_uv = models.iter().any(|o| !o.mesh.texcoords.is_empty());
    for o in &models {
        let t = &o.mesh;
        let n = t.positions.len() / 3;
        let base = m.positions.len() as u32;
        if let Some(&i) = t.indices.iter().find(|&&i| i as usize >= n) {
            return Err(bad(format!(
                "object '{}': index {} is past its {n} vertices",
                o.name,
                i + 1
            )));
        }
        m.positions.extend(
            t.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        let normals = t.normals.len() == t.positions.len();
        has_normal.extend(std::iter::repeat_n(normals, n));
        match normals {
            true => m.normals.extend(
                t.normals
                    .chunks_exact(3)
                    .map(|p| Vec3::new(p[0], p[1], p[2])),
            ),
            false => m.normals.extend(std::iter::repeat_n(Vec3::ZERO, n)),
        }
        if any_uv {
            match t.texcoords.len() == 2 * n {
                true => m
                    .uvs
                    .extend(t.texcoords.chunks_exact(2).map(|p| Vec2::new(p[0], p[1]))),
                false => m.uvs.extend(std::iter::repeat_n(Vec2::ZERO, n)),
            }
        }
        m.indices.extend(t.indices.iter().map(|i| i + base));
    }
    if m.indices.is_empty() {
        return Err(bad("has no faces".into()));
    }
    if m.positions.iter().any(|p| !p.is_finite()) {
        return Err(bad("has a non-finite vertex position".into()));
    }
    let n = m.positions.len();
    m.joints = vec![[0; MAX_INFLUENCES]; n];
    m.weights = vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]; n];
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    super::assemble(
        path.display().to_string(),
        (m, has_normal),
        Skeleton::single(&name),
        Vec::new(),
        false,
        Vec::new(),
    )
}
