//! A character as loaded: one triangle mesh whose every vertex is skinned to a joint list
//! (a rigid mesh is skinned to its own node with weight 1), the node hierarchy, and clips.
use super::check::MeshCheck;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

/// Joints one character may have (the joint buffer holds them all).
pub const MAX_JOINTS: usize = 1024;

/// Influences per vertex: JOINTS_0/WEIGHTS_0 and, when present, JOINTS_1/WEIGHTS_1.
pub const MAX_INFLUENCES: usize = 8;

#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Empty when the file has no texture coordinates.
    pub uvs: Vec<Vec2>,
    /// Triangles, three indices each.
    pub indices: Vec<u32>,
    /// Per vertex, sorted by weight (largest first); unused slots have weight 0.
    pub joints: Vec<[u16; MAX_INFLUENCES]>,
    pub weights: Vec<[f32; MAX_INFLUENCES]>,
    /// 1: at most 4 influences per vertex; 2: up to 8.
    pub influence_sets: usize,
    /// Triangle ranges with UVs of their own (a file's primitives), packed apart in the
    /// emission atlas; empty: the whole mesh is one UV set.
    pub uv_parts: Vec<UvPart>,
    /// Morph targets, added to the rest vertices before skinning.
    pub morphs: Morphs,
}

/// Morph targets: each a weight slot (one per target of each mesh node that has some), and
/// per vertex its nonzero offsets, by vertex (CSR) so skinning reads only its own.
#[derive(Clone, Debug, Default)]
pub struct Morphs {
    pub targets: Vec<MorphTarget>,
    /// Vertex v's offsets are `deltas[start[v]..start[v + 1]]`; empty without targets.
    pub start: Vec<u32>,
    pub deltas: Vec<MorphDelta>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct MorphTarget {
    /// The file's target name (the mesh's `extras.targetNames`), else "target K".
    pub name: String,
    /// The mesh node whose `weights` drive it, and its index among that mesh's targets.
    pub node: usize,
    pub index: usize,
    /// The node's (else the mesh's, else 0) default weight.
    pub default: f32,
    /// Whether the file gave normal offsets (else normals do not follow).
    pub normals: bool,
}

/// One vertex's offsets in one target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MorphDelta {
    pub target: u32,
    pub position: Vec3,
    pub normal: Vec3,
}

impl Morphs {
    /// The default weight of every target.
    pub fn defaults(&self) -> Vec<f32> {
        self.targets.iter().map(|t| t.default).collect()
    }

    /// Vertex `v`'s position and normal with the targets at `weights`.
    pub fn apply(&self, v: usize, p: Vec3, n: Vec3, weights: &[f32]) -> (Vec3, Vec3) {
        let Some(range) = self.start.get(v..v + 2) else {
            return (p, n);
        };
        let (mut p, mut n) = (p, n);
        for d in &self.deltas[range[0] as usize..range[1] as usize] {
            let w = weights.get(d.target as usize).copied().unwrap_or(0.0);
            p += d.position * w;
            n += d.normal * w;
        }
        (p, n)
    }
}

/// `count` triangles from `first` sharing one UV set.
#[derive(Clone, Debug, PartialEq)]
pub struct UvPart {
    pub name: String,
    pub first: u32,
    pub count: u32,
}

impl Mesh {
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn vertices(&self) -> usize {
        self.positions.len()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    pub t: Vec3,
    pub r: Quat,
    pub s: Vec3,
}

impl Default for Trs {
    fn default() -> Self {
        Self {
            t: Vec3::ZERO,
            r: Quat::IDENTITY,
            s: Vec3::ONE,
        }
    }
}

impl Trs {
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.s, self.r, self.t)
    }
}

#[derive(Clone, Debug)]
pub struct Node {
    pub name: String,
    pub parent: Option<usize>,
    pub rest: Trs,
}

#[derive(Clone, Debug)]
pub struct Joint {
    pub node: usize,
    pub inverse_bind: Mat4,
}

#[derive(Clone, Debug, Default)]
pub struct Skeleton {
    pub nodes: Vec<Node>,
    pub joints: Vec<Joint>,
    /// Node indices, every parent before its children.
    pub order: Vec<usize>,
}

impl Skeleton {
    /// One node, one joint: a static mesh.
    pub fn single(name: &str) -> Self {
        Self {
            nodes: vec![Node {
                name: name.into(),
                parent: None,
                rest: Trs::default(),
            }],
            joints: vec![Joint {
                node: 0,
                inverse_bind: Mat4::IDENTITY,
            }],
            order: vec![0],
        }
    }

    /// Global transforms of every node from their local transforms.
    pub fn globals(&self, locals: &[Trs]) -> Vec<Mat4> {
        let mut g = vec![Mat4::IDENTITY; self.nodes.len()];
        for &i in &self.order {
            let m = locals[i].matrix();
            g[i] = match self.nodes[i].parent {
                Some(p) => g[p] * m,
                None => m,
            };
        }
        g
    }

    pub fn rest_locals(&self) -> Vec<Trs> {
        self.nodes.iter().map(|n| n.rest).collect()
    }

    /// Joint matrices (joint global x inverse bind) for node globals.
    pub fn joint_matrices(&self, globals: &[Mat4]) -> Vec<Mat4> {
        self.joints
            .iter()
            .map(|j| globals[j.node] * j.inverse_bind)
            .collect()
    }

    /// Parents-first order of the nodes (fails on a cycle).
    pub fn sort(nodes: &[Node]) -> Option<Vec<usize>> {
        let mut order = Vec::with_capacity(nodes.len());
        let mut state = vec![0u8; nodes.len()]; // 0 new, 1 visiting, 2 done
        fn visit(i: usize, nodes: &[Node], st: &mut [u8], out: &mut Vec<usize>) -> bool {
            match st[i] {
                2 => return true,
                1 => return false,
                _ => {}
            }
            st[i] = 1;
            if let Some(p) = nodes[i].parent {
                if !visit(p, nodes, st, out) {
                    return false;
                }
            }
            st[i] = 2;
            out.push(i);
            true
        }
        for i in 0..nodes.len() {
            if !visit(i, nodes, &mut state, &mut order) {
                return None;
            }
        }
        Some(order)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interp {
    Step,
    Linear,
    CubicSpline,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    Translation,
    Rotation,
    Scale,
    /// The node's morph target K (a glTF `weights` channel, split per target; value in x).
    Weight(u16),
}

/// One animated property of one node. Values are xyz(w); CUBICSPLINE stores three per key
/// (in-tangent, value, out-tangent).
#[derive(Clone, Debug)]
pub struct Channel {
    pub node: usize,
    pub property: Property,
    pub interp: Interp,
    pub times: Vec<f32>,
    pub values: Vec<Vec4>,
}

#[derive(Clone, Debug)]
pub struct Clip {
    pub name: String,
    /// Last key time of any channel (seconds).
    pub duration: f32,
    pub channels: Vec<Channel>,
}

/// One mesh node of a file, as `inspect` and a run's report list it: its primitives'
/// triangles, what places it, its morph targets and whether it is closed by itself.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshPart {
    pub node: String,
    pub mesh: String,
    pub primitives: usize,
    pub triangles: usize,
    /// "skin K 'name' (N joints)", or "rigid, follows its node".
    pub placed_by: String,
    pub morph_targets: usize,
    pub boundary_edges: usize,
    pub nonmanifold_edges: usize,
    pub components: usize,
}

impl MeshPart {
    pub fn closed(&self) -> bool {
        self.boundary_edges == 0 && self.nonmanifold_edges == 0
    }
}

/// Everything `inspect` reports and the scene needs.
#[derive(Clone, Debug)]
pub struct Character {
    /// The file (or built-in name) it came from.
    pub source: String,
    pub mesh: Mesh,
    pub skeleton: Skeleton,
    pub clips: Vec<Clip>,
    /// The file had a skin (false: a static mesh, rigidly attached to its nodes).
    pub skinned: bool,
    /// Vertices as stored, before welding.
    pub raw_vertices: usize,
    pub normals_computed: bool,
    pub check: MeshCheck,
    /// The mesh faced inward and was flipped.
    pub flipped: bool,
    pub warnings: Vec<String>,
    /// The file's mesh nodes (glTF; empty for OBJ and built-in shapes: one part).
    pub parts: Vec<MeshPart>,
    /// The built-in characters' capsules (empty for loaded ones: capsules::of fits them).
    pub capsules: Vec<super::capsules::BoneCapsule>,
}
