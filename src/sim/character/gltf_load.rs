//! glTF 2.0 (.glb, .gltf with embedded, data-URI or external buffers) -> `Character`.
//! Every triangle primitive of every mesh node in the scene; skinned meshes keep their
//! vertices in bind space (joint matrices ignore the mesh node's transform, as the spec
//! requires); rigid meshes become skinned to their own node with weight 1.
use super::model::*;
use crate::error::{Error, Result};
use glam::{Mat4, Quat, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

pub(super) fn err(path: &Path, message: impl Into<String>) -> Error {
    Error::Model {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// Refuse an accessor the gltf reader would panic on: empty, or of a type the spec does
/// not allow for its use (`allowed`: dimensions and component types).
pub(super) fn check_accessor(
    path: &Path,
    what: &str,
    a: &gltf::Accessor,
    allowed: &[(Dimensions, &[DataType])],
) -> Result<()> {
    if a.count() == 0 || a.sparse().is_some_and(|s| s.count() == 0) {
        return Err(err(
            path,
            format!("{what}: accessor {} is empty", a.index()),
        ));
    }
    let ok = allowed
        .iter()
        .any(|(d, types)| *d == a.dimensions() && types.contains(&a.data_type()));
    match ok {
        true => Ok(()),
        false => Err(err(
            path,
            format!(
                "{what}: accessor {} is {:?} of {:?}, which the glTF spec does not allow there",
                a.index(),
                a.dimensions(),
                a.data_type()
            ),
        )),
    }
}

/// Every attribute the loader reads has POSITION's count and an allowed type; the index
/// accessor too.
fn check_primitive(path: &Path, what: &str, prim: &gltf::Primitive, quantized: bool) -> Result<()> {
    use gltf::Semantic as S;
    use DataType::{F32, U16, U32, U8};
    let n = prim.get(&S::Positions).map(|a| a.count());
    for (sem, a) in prim.attributes() {
        let allowed: &[(Dimensions, &[DataType])] = match &sem {
            S::Joints(_) => &[(Dimensions::Vec4, &[U8, U16])],
            S::Weights(_) => &[(Dimensions::Vec4, &[F32, U8, U16])],
            s => match super::gltf_quantized::allowed(s, quantized) {
                Some(types) => &[(super::gltf_quantized::dims(s), types)],
                None => continue,
            },
        };
        let label = format!("{what} {sem:?}");
        check_accessor(path, &label, &a, allowed)?;
        if Some(a.count()) != n {
            return Err(err(
                path,
                format!(
                    "{label} has {} entries for {} vertices",
                    a.count(),
                    n.unwrap_or(0)
                ),
            ));
        }
    }
    if let Some(a) = prim.indices() {
        check_accessor(
            path,
            &format!("{what} indices"),
            &a,
            &[(Dimensions::Scalar, &[U8, U16, U32])],
        )?;
    }
    Ok(())
}

fn check_joint_count(path: &Path, n: usize) -> Result<()> {
    match n > MAX_JOINTS {
        true => Err(err(
            path,
            format!("has {n} joints; at most {MAX_JOINTS} are supported"),
        )),
        false => Ok(()),
    }
}

/// One primitive's vertices before merging.
struct Part {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Option<Vec<Vec2>>,
    indices: Vec<u32>,
    influences: Vec<Vec<(u16, f32)>>,
    /// The joint a vertex with all-zero weights is bound to (its skin's first, or its node).
    fallback: u16,
    /// Its morph targets: weight slot, position and normal offsets per vertex.
    morphs: Vec<super::gltf_morphs::PartTarget>,
}

pub fn load(path: &Path) -> Result<Character> {
    let opened = super::gltf_files::open(path)?;
    let doc = &opened.doc;
    let buffers = super::gltf_quantized::Buffers {
        data: opened.buffers,
        quantized: opened.quantized,
    };
    let mut warnings = Vec::new();
    let nodes = read_nodes(doc);
    let order =
        Skeleton::sort(&nodes).ok_or_else(|| err(path, "its node hierarchy has a cycle"))?;

    let mut joints = Joints::default();
    let mut parts = Vec::new();
    let mut skinned = false;
    let mut targets: Vec<MorphTarget> = Vec::new();
    let mut infos = Vec::new();
    let mut computed_normals = false;
    for ni in scene_nodes(doc, &nodes) {
        let node = doc.nodes().nth(ni).unwrap();
        let Some(mesh) = node.mesh() else { continue };
        let (offset, skin_joints) = joints.of_node(path, &node, &buffers)?;
        skinned |= skin_joints.is_some();
        let slots = targets.len() as u32;
        targets.extend(super::gltf_morphs::targets(&node, &mesh));
        let first_part = parts.len();
        for prim in mesh.primitives() {
            let what = format!(
                "mesh {} ('{}') primitive {}",
                mesh.index(),
                mesh.name().unwrap_or(""),
                prim.index()
            );
            let (mut part, computed) = read_part(
                path,
                &what,
                &prim,
                &buffers,
                offset,
                skin_joints,
                &mut warnings,
            )?;
            computed_normals |= computed;
            part.morphs = super::gltf_morphs::read(path, &what, &prim, &buffers, slots)?;
            for (slot, _, n) in &part.morphs {
                targets[*slot as usize].normals |= n.iter().any(|v| *v != Vec3::ZERO);
            }
            parts.push(part);
        }
        infos.push(part_info(
            &node,
            &mesh,
            &parts[first_part..],
            skin_joints.is_some(),
        ));
    }
    if parts.is_empty() {
        return Err(err(path, "has no mesh in its scene"));
    }
    // Rigid mesh nodes add a joint each.
    check_joint_count(path, joints.list.len())?;
    let clips = super::gltf_clips::read_clips(path, doc, &buffers, &mut warnings)?;
    let skeleton = Skeleton {
        nodes,
        joints: joints.list,
        order,
    };
    let mut ch = super::assemble(
        path.display().to_string(),
        merge(parts, targets, &mut warnings),
        skeleton,
        clips,
        skinned,
        warnings,
    )?;
    ch.normals_computed |= computed_normals;
    ch.parts = infos;
    Ok(ch)
}

/// What `inspect` and the run's report say of one mesh node: its primitives checked
/// together (in the mesh's own space: welding and edges do not depend on the pose).
fn part_info(node: &gltf::Node, mesh: &gltf::Mesh, parts: &[Part], skinned: bool) -> MeshPart {
    let (mut pos, mut idx) = (Vec::new(), Vec::new());
    for p in parts {
        let base = pos.len() as u32;
        pos.extend(&p.positions);
        idx.extend(p.indices.iter().map(|i| i + base));
    }
    let c = super::check::check(&pos, &idx);
    let name = |n: Option<&str>, what: &str, i: usize| {
        n.map_or_else(|| format!("{what}{i}"), str::to_string)
    };
    MeshPart {
        node: name(node.name(), "node", node.index()),
        mesh: name(mesh.name(), "mesh", mesh.index()),
        primitives: parts.len(),
        triangles: idx.len() / 3,
        placed_by: match (skinned, node.skin()) {
            (true, Some(s)) => format!(
                "skin {} '{}' ({} joints)",
                s.index(),
                s.name().unwrap_or(""),
                s.joints().count()
            ),
            _ => "rigid, follows its node".into(),
        },
        morph_targets: parts.iter().map(|p| p.morphs.len()).max().unwrap_or(0),
        boundary_edges: c.boundary_edges,
        nonmanifold_edges: c.nonmanifold_edges,
        components: c.components,
    }
}

/// Every node with its rest transform and parent.
fn read_nodes(doc: &gltf::Document) -> Vec<Node> {
    let mut nodes: Vec<Node> = doc
        .nodes()
        .map(|n| {
            let (t, r, s) = n.transform().decomposed();
            Node {
                name: n
                    .name()
                    .map(str::to_string)
                    .unwrap_or_else(|| format!("node{}", n.index())),
                parent: None,
                rest: Trs {
                    t: Vec3::from(t),
                    r: Quat::from_array(r).normalize(),
                    s: Vec3::from(s),
                },
            }
        })
        .collect();
    for n in doc.nodes() {
        for c in n.children() {
            nodes[c.index()].parent = Some(n.index());
        }
    }
    nodes
}

/// Nodes of the scene shown (the default scene, else the first, else every root), sorted.
fn scene_nodes(doc: &gltf::Document, nodes: &[Node]) -> Vec<usize> {
    let roots: Vec<usize> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().map(|n| n.index()).collect(),
        None => (0..nodes.len())
            .filter(|&i| nodes[i].parent.is_none())
            .collect(),
    };
    let mut stack = roots;
    let mut in_scene = Vec::new();
    while let Some(i) = stack.pop() {
        in_scene.push(i);
        stack.extend(doc.nodes().nth(i).unwrap().children().map(|c| c.index()));
    }
    in_scene.sort_unstable();
    in_scene
}

/// The skeleton's joints as mesh nodes name them: each skin's joints once, and one joint
/// for each rigid mesh node.
#[derive(Default)]
struct Joints {
    list: Vec<Joint>,
    skin_offset: HashMap<usize, usize>,
    rigid_joint: HashMap<usize, usize>,
}

impl Joints {
    /// Where a mesh node's joint indices start in the list, and its skin's joint count
    /// (None for a rigid node).
    fn of_node(
        &mut self,
        path: &Path,
        node: &gltf::Node,
        buffers: &[gltf::buffer::Data],
    ) -> Result<(usize, Option<usize>)> {
        let Some(skin) = node.skin() else {
            let list = &mut self.list;
            let o = *self.rigid_joint.entry(node.index()).or_insert_with(|| {
                list.push(Joint {
                    node: node.index(),
                    inverse_bind: Mat4::IDENTITY,
                });
                list.len() - 1
            });
            return Ok((o, None));
        };
        let n = skin.joints().count();
        if let Some(&o) = self.skin_offset.get(&skin.index()) {
            return Ok((o, Some(n)));
        }
        let o = self.list.len();
        let label = format!("skin {}", skin.index());
        if n == 0 {
            return Err(err(path, format!("{label} has no joints")));
        }
        if let Some(a) = skin.inverse_bind_matrices() {
            check_accessor(path, &label, &a, &[(Dimensions::Mat4, &[DataType::F32])])?;
        }
        let ibm: Vec<Mat4> = match skin
            .reader(|b| Some(&buffers[b.index()]))
            .read_inverse_bind_matrices()
        {
            Some(it) => it.map(|m| Mat4::from_cols_array_2d(&m)).collect(),
            None => vec![Mat4::IDENTITY; n],
        };
        if ibm.len() < n {
            return Err(err(
                path,
                format!(
                    "skin {} has {} inverse bind matrices for {n} joints",
                    skin.index(),
                    ibm.len()
                ),
            ));
        }
        for (j, jn) in skin.joints().enumerate() {
            self.list.push(Joint {
                node: jn.index(),
                inverse_bind: ibm[j],
            });
        }
        // Before the skin's primitives are read, so the count is the error.
        check_joint_count(path, self.list.len())?;
        self.skin_offset.insert(skin.index(), o);
        Ok((o, Some(n)))
    }
}

/// One primitive's vertices, with joint indices offset into the skeleton's list; true
/// when its normals had to be computed.
fn read_part(
    path: &Path,
    what: &str,
    prim: &gltf::Primitive,
    buffers: &super::gltf_quantized::Buffers,
    offset: usize,
    skin_joints: Option<usize>,
    warnings: &mut Vec<String>,
) -> Result<(Part, bool)> {
    use super::gltf_quantized::floats;
    check_primitive(path, what, prim, buffers.quantized)?;
    let reader = prim.reader(|b| Some(&buffers[b.index()]));
    let attr = |s: gltf::Semantic| prim.get(&s);
    let a = attr(gltf::Semantic::Positions)
        .ok_or_else(|| err(path, format!("{what} has no POSITION")))?;
    let positions: Vec<Vec3> = floats::<3>(path, what, &a, buffers)?
        .into_iter()
        .map(Vec3::from)
        .collect();
    let n = positions.len();
    let list: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if let Some(&bad) = list.iter().find(|&&i| i as usize >= n) {
        return Err(err(
            path,
            format!("{what}: index {bad} is past its {n} vertices"),
        ));
    }
    let indices = triangles(prim.mode(), &list).ok_or_else(|| {
        err(path, format!("{what} draws {:?}; only triangle primitives (triangles, strips, fans) can be loaded", prim.mode()))
    })?;
    // Quantized normals are unit only to their precision.
    let normals = match attr(gltf::Semantic::Normals) {
        Some(a) => {
            let unit = a.data_type() != DataType::F32;
            let v = floats::<3>(path, what, &a, buffers)?
                .into_iter()
                .map(Vec3::from);
            Some(match unit {
                true => v.map(Vec3::normalize_or_zero).collect::<Vec<_>>(),
                false => v.collect(),
            })
        }
        None => None,
    };
    let uvs = match attr(gltf::Semantic::TexCoords(0)) {
        Some(a) => {
            let mut uv: Vec<Vec2> = floats::<2>(path, what, &a, buffers)?
                .into_iter()
                .map(Vec2::from)
                .collect();
            super::gltf_quantized::transform_uvs(prim, &mut uv);
            Some(uv)
        }
        None => None,
    };
    let influences = match skin_joints {
        Some(count) => read_influences(path, what, &reader, n, offset, count, warnings)?,
        None => vec![vec![(offset as u16, 1.0)]; n],
    };
    // Normals computed per part: parts stored in their own nodes' spaces may overlap.
    let computed = normals.is_none();
    let normals = normals.unwrap_or_else(|| super::check::area_normals(&positions, &indices));
    let part = Part {
        positions,
        normals,
        uvs,
        indices,
        influences,
        fallback: offset as u16,
        morphs: Vec::new(),
    };
    Ok((part, computed))
}

/// A skinned primitive's joint influences from JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1.
fn read_influences<'a, 's, F>(
    path: &Path,
    what: &str,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    n: usize,
    offset: usize,
    count: usize,
    warnings: &mut Vec<String>,
) -> Result<Vec<Vec<(u16, f32)>>>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let mut influences = vec![Vec::new(); n];
    let mut sets = 0;
    for set in 0..3u32 {
        let (Some(js), Some(ws)) = (reader.read_joints(set), reader.read_weights(set)) else {
            break;
        };
        if set == 2 {
            warnings.push(format!("{what}: JOINTS_2 and later sets are ignored (at most {MAX_INFLUENCES} influences per vertex)"));
            break;
        }
        sets += 1;
        for (v, (j, w)) in js.into_u16().zip(ws.into_f32()).enumerate() {
            for k in 0..4 {
                if w[k] > 0.0 && w[k].is_finite() {
                    if j[k] as usize >= count {
                        return Err(err(
                            path,
                            format!(
                                "{what}: vertex {v} names joint {} of a skin with {count}",
                                j[k]
                            ),
                        ));
                    }
                    influences[v].push(((offset + j[k] as usize) as u16, w[k]));
                }
            }
        }
    }
    if sets == 0 {
        return Err(err(
            path,
            format!("{what} belongs to a skinned node but has no JOINTS_0/WEIGHTS_0"),
        ));
    }
    Ok(influences)
}

/// Triangle list of a primitive's index list, or None for points and lines.
fn triangles(mode: Mode, list: &[u32]) -> Option<Vec<u32>> {
    Some(match mode {
        Mode::Triangles => list[..list.len() / 3 * 3].to_vec(),
        Mode::TriangleStrip => (2..list.len())
            .flat_map(|i| match i % 2 {
                0 => [list[i - 2], list[i - 1], list[i]],
                _ => [list[i - 1], list[i - 2], list[i]],
            })
            .collect(),
        Mode::TriangleFan => (2..list.len())
            .flat_map(|i| [list[0], list[i - 1], list[i]])
            .collect(),
        _ => return None,
    })
}

/// One mesh of all parts: influences renormalised and sorted, normals where parts have them.
fn merge(
    parts: Vec<Part>,
    targets: Vec<MorphTarget>,
    warnings: &mut Vec<String>,
) -> (Mesh, Vec<bool>) {
    let mut m = Mesh {
        influence_sets: 1,
        ..Default::default()
    };
    if !targets.is_empty() {
        m.morphs.targets = targets;
        m.morphs.start.push(0);
    }
    let mut has_normal = Vec::new();
    let any_uv = parts.iter().any(|p| p.uvs.is_some());
    let mut zero = 0;
    let mut over = 0;
    for (k, p) in parts.into_iter().enumerate() {
        let base = m.positions.len() as u32;
        let n = p.positions.len();
        if p.uvs.is_some() {
            m.uv_parts.push(UvPart {
                name: format!("primitive {k}"),
                first: (m.indices.len() / 3) as u32,
                count: (p.indices.len() / 3) as u32,
            });
        }
        m.indices.extend(p.indices.iter().map(|i| i + base));
        if !m.morphs.targets.is_empty() {
            super::gltf_morphs::append(&mut m.morphs, &p.morphs, n);
        }
        m.positions.extend(&p.positions);
        has_normal.extend(std::iter::repeat_n(true, n));
        m.normals.extend(p.normals);
        if any_uv {
            m.uvs.extend(p.uvs.unwrap_or_else(|| vec![Vec2::ZERO; n]));
        }
        for mut inf in p.influences {
            inf.sort_by(|a, b| b.1.total_cmp(&a.1));
            if inf.len() > MAX_INFLUENCES {
                over += 1;
                inf.truncate(MAX_INFLUENCES);
            }
            let sum: f32 = inf.iter().map(|x| x.1).sum();
            if !(sum > 0.0 && sum.is_finite()) {
                zero += 1;
                inf = vec![(p.fallback, 1.0)];
            }
            let sum: f32 = inf.iter().map(|x| x.1).sum();
            if inf.len() > 4 {
                m.influence_sets = 2;
            }
            let (mut j, mut w) = ([0u16; MAX_INFLUENCES], [0f32; MAX_INFLUENCES]);
            for (k, (id, wt)) in inf.into_iter().enumerate() {
                j[k] = id;
                w[k] = wt / sum;
            }
            m.joints.push(j);
            m.weights.push(w);
        }
    }
    if zero > 0 {
        warnings.push(format!(
            "{zero} vertices have all-zero weights; bound to joint 0"
        ));
    }
    if over > 0 {
        warnings.push(format!(
            "{over} vertices had more than {MAX_INFLUENCES} influences; the lightest were dropped"
        ));
    }
    (m, has_normal)
}

/// Percent-decoding of a relative URI (spaces and the like in file names).
pub(super) fn urlencoding_decode(uri: &str) -> String {
    urlencoding::decode(uri)
        .map(|c| c.into_owned())
        .unwrap_or_else(|_| uri.to_string())
}
