//! glTF morph targets -> `Morphs`: a weight slot per target of each mesh node (named by the
//! mesh's `extras.targetNames`, defaults from the node's or the mesh's `weights`), and each
//! primitive's position and normal offsets, checked like its attributes.
use super::gltf_load::{check_accessor, err};
use super::model::{MorphDelta, MorphTarget, Morphs};
use crate::error::Result;
use glam::Vec3;
use gltf::accessor::Dimensions;
use std::path::Path;

/// One primitive's target: its weight slot, position and normal offsets per vertex.
pub(super) type PartTarget = (u32, Vec<Vec3>, Vec<Vec3>);

/// The weight slots of mesh node `node`: as many as its mesh's primitives have targets.
pub(super) fn targets(node: &gltf::Node, mesh: &gltf::Mesh) -> Vec<MorphTarget> {
    let count = mesh
        .primitives()
        .map(|p| p.morph_targets().count())
        .max()
        .unwrap_or(0);
    let names: Vec<String> = mesh
        .extras()
        .as_ref()
        .and_then(|x| serde_json::from_str::<serde_json::Value>(x.get()).ok())
        .and_then(|v| v.get("targetNames").cloned())
        .and_then(|v| serde_json::from_value(v).ok())
        .unwrap_or_default();
    let defaults = node.weights().or(mesh.weights()).unwrap_or(&[]);
    (0..count)
        .map(|k| MorphTarget {
            name: names
                .get(k)
                .cloned()
                .unwrap_or_else(|| format!("target {k}")),
            node: node.index(),
            index: k,
            default: defaults.get(k).copied().unwrap_or(0.0),
            normals: false,
        })
        .collect()
}

/// A primitive's targets (slots from `first`): offsets per vertex, every accessor of
/// POSITION's count and of the type the spec allows.
pub(super) fn read(
    path: &Path,
    what: &str,
    prim: &gltf::Primitive,
    buffers: &super::gltf_quantized::Buffers,
    first: u32,
) -> Result<Vec<PartTarget>> {
    let n = prim
        .get(&gltf::Semantic::Positions)
        .map_or(0, |a| a.count());
    for (k, t) in prim.morph_targets().enumerate() {
        for (attr, a) in [("POSITION", t.positions()), ("NORMAL", t.normals())] {
            let Some(a) = a else { continue };
            let label = format!("{what} morph target {k} {attr}");
            let types = super::gltf_quantized::morph_allowed(buffers.quantized);
            check_accessor(path, &label, &a, &[(Dimensions::Vec3, types)])?;
            if a.count() != n {
                return Err(err(
                    path,
                    format!("{label} has {} entries for {n} vertices", a.count()),
                ));
            }
        }
    }
    let offsets = |a: Option<gltf::Accessor>, label: String| -> Result<Vec<Vec3>> {
        match a {
            Some(a) => Ok(
                super::gltf_quantized::floats::<3>(path, &label, &a, buffers)?
                    .into_iter()
                    .map(Vec3::from)
                    .collect(),
            ),
            None => Ok(vec![Vec3::ZERO; n]),
        }
    };
    prim.morph_targets()
        .enumerate()
        .map(|(k, t)| {
            let label = format!("{what} morph target {k}");
            let p = offsets(t.positions(), format!("{label} POSITION"))?;
            let nrm = offsets(t.normals(), format!("{label} NORMAL"))?;
            Ok((first + k as u32, p, nrm))
        })
        .collect()
}

/// Append a part's `n` vertices' offsets (its nonzero ones) to the merged CSR.
pub(super) fn append(m: &mut Morphs, part: &[PartTarget], n: usize) {
    for v in 0..n {
        for (slot, p, nrm) in part {
            if p[v] != Vec3::ZERO || nrm[v] != Vec3::ZERO {
                m.deltas.push(MorphDelta {
                    target: *slot,
                    position: p[v],
                    normal: nrm[v],
                });
            }
        }
        m.start.push(m.deltas.len() as u32);
    }
}
