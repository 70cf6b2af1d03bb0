//! The skinning pass (`skin` scope): positions and normals of every vertex from the joint
//! matrices uploaded each frame. Sized buffers (`SkinnedMesh`) apart from the pipeline.
use super::model::Mesh;
use super::pose::GpuJoint;
use crate::character::Skinning;
use crate::error::{Error, Result};
use crate::gpu::pass::{Defines, PassKey};
use crate::gpu::vk;
use crate::gpu::{Buffer, ComputePipeline, Context, Guard};
use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SkinPush {
    pub n: u32,
    /// 1 when the mesh has morph targets: a mesh without skips their ranges (a uniform
    /// branch) instead of reading an empty one per vertex.
    pub morphs: u32,
}

crate::gpu_interface! {
    /// glsl/character/skin.comp
    pub SkinIo / SkinBufs: "SKIN", push SkinPush {
        joints = 0, rest_pos = 1, rest_nrm = 2, joint_ids = 3, weights = 4, out_pos = 5, out_nrm = 6,
        morph_start = 7, morph_deltas = 8, morph_weights = 9,
    }
}

pub struct SkinPass {
    pipeline: ComputePipeline<SkinIo>,
    pub method: Skinning,
    pub sets: usize,
}

/// The skinning shader's variant: the method and the influence sets (1: 4 per vertex, 2: 8).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SkinKey {
    pub method: Skinning,
    pub sets: usize,
}

impl PassKey for SkinKey {
    fn all() -> Vec<Self> {
        let methods = Skinning::all().iter();
        methods
            .flat_map(|m| [1, 2].map(|sets| Self { method: *m, sets }))
            .collect()
    }
    fn defines(&self) -> Defines {
        let d = SkinPass::defines(self.method, self.sets).into_iter();
        d.map(|(k, v)| (k.to_string(), v)).collect()
    }
}

crate::gpu::compute_pass!(pub SKIN: SkinIo, SkinKey = "skin", "character/skin.comp");

impl SkinPass {
    pub fn defines(method: Skinning, sets: usize) -> Vec<(&'static str, String)> {
        let m = match method {
            Skinning::Lbs => 0,
            Skinning::Dqs => 1,
        };
        vec![
            ("SKIN_METHOD", m.to_string()),
            ("SKIN_SETS", sets.to_string()),
        ]
    }

    /// For meshes of `sets` influence sets (1: 4 per vertex, 2: 8).
    pub fn new(ctx: &Context, method: Skinning, sets: usize) -> Result<Self> {
        Ok(Self {
            pipeline: SKIN.pipeline(ctx, &SkinKey { method, sets }, 64, &[])?,
            method,
            sets,
        })
    }

    /// Skin `m` with the joints its last `set_pose` wrote (made visible by the caller).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, m: &SkinnedMesh) -> Result<()> {
        if m.sets != self.sets {
            return Err(Error::Param(format!(
                "skinning pass for {} influence sets given a mesh with {}",
                self.sets, m.sets
            )));
        }
        let bufs = SkinBufs {
            joints: &m.joints,
            rest_pos: &m.rest_pos,
            rest_nrm: &m.rest_nrm,
            joint_ids: &m.joint_ids,
            weights: &m.weights,
            out_pos: &m.pos,
            out_nrm: &m.nrm,
            morph_start: &m.morph_start,
            morph_deltas: &m.morph_deltas,
            morph_weights: &m.morph_weights,
        };
        self.pipeline.dispatch(
            ctx,
            cmd,
            &bufs,
            &SkinPush {
                n: m.vertices,
                morphs: (m.targets > 0) as u32,
            },
            m.vertices as u64,
        );
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
crate::impl_destroy!(SkinPass);

/// A mesh on the GPU: rest vertices and influences, morph targets (each vertex's offsets,
/// by vertex), the joints and target weights, the skinned output (vec4 positions and
/// normals) and the triangle indices for drawing.
pub struct SkinnedMesh {
    pub joints: Buffer,
    morph_start: Buffer,
    morph_deltas: Buffer,
    morph_weights: Buffer,
    /// Morph targets (weights `set_weights` takes).
    pub targets: usize,
    rest_pos: Buffer,
    rest_nrm: Buffer,
    joint_ids: Buffer,
    weights: Buffer,
    pub pos: Buffer,
    pub nrm: Buffer,
    pub indices: Buffer,
    pub vertices: u32,
    pub triangles: u32,
    pub joint_count: usize,
    pub sets: usize,
}

impl SkinnedMesh {
    pub fn new(ctx: &Context, mesh: &Mesh, joint_count: usize) -> Result<Self> {
        Self::tagged(ctx, mesh, joint_count, None)
    }

    /// With a value per vertex that skinning carries along in the positions' w (the
    /// control particles' fill of the shape; 1 without).
    pub fn tagged(
        ctx: &Context,
        mesh: &Mesh,
        joint_count: usize,
        tags: Option<&[f32]>,
    ) -> Result<Self> {
        let n = mesh.vertices();
        let sets = mesh.influence_sets;
        let v4 = |v: &glam::Vec3, w: f32| [v.x, v.y, v.z, w];
        let tag = |i: usize| tags.and_then(|t| t.get(i).copied()).unwrap_or(1.0);
        let pos: Vec<[f32; 4]> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| v4(p, tag(i)))
            .collect();
        let nrm: Vec<[f32; 4]> = mesh.normals.iter().map(|p| v4(p, 0.0)).collect();
        let mut ids = Vec::with_capacity(n * sets);
        let mut ws = Vec::with_capacity(n * sets);
        for v in 0..n {
            for s in 0..sets {
                let j = &mesh.joints[v][4 * s..4 * s + 4];
                ids.push([
                    j[0] as u32 | (j[1] as u32) << 16,
                    j[2] as u32 | (j[3] as u32) << 16,
                ]);
                let w = &mesh.weights[v][4 * s..4 * s + 4];
                ws.push([w[0], w[1], w[2], w[3]]);
            }
        }
        // Each buffer guarded: a failure halfway releases the ones made before it.
        let buf =
            |name: &str, size: u64| ctx.storage_buffer(name, size).map(|b| Guard::new(ctx, b));
        let vb = n as u64 * 16;
        let joints = buf(
            "skin joints",
            (joint_count * std::mem::size_of::<GpuJoint>()) as u64,
        )?;
        let mut rest_pos = buf("skin rest positions", vb)?;
        let mut rest_nrm = buf("skin rest normals", vb)?;
        let mut joint_ids = buf("skin joint ids", (n * sets * 8) as u64)?;
        let mut weights = buf("skin weights", (n * sets * 16) as u64)?;
        let out_pos = buf("skinned positions", vb)?;
        let out_nrm = buf("skinned normals", vb)?;
        let mut indices = buf("mesh indices", mesh.indices.len() as u64 * 4)?;
        // Morph offsets: per vertex a range of (position, target bits) and normal pairs.
        let m = &mesh.morphs;
        let start = match m.start.len() == n + 1 {
            true => m.start.clone(),
            false => vec![0u32; n + 1],
        };
        let deltas: Vec<[f32; 4]> = (m.deltas.iter())
            .flat_map(|d| {
                // The target's index as a float's value (exact below 2^24; not its bits,
                // which would be a denormal a device may flush).
                let t = d.target as f32;
                [
                    d.position.extend(t).to_array(),
                    d.normal.extend(0.0).to_array(),
                ]
            })
            .collect();
        let targets = m.targets.len();
        let mut morph_start = buf("morph starts", start.len() as u64 * 4)?;
        let mut morph_deltas = buf("morph offsets", (deltas.len() as u64 * 16).max(32))?;
        let mut morph_weights = buf("morph weights", (targets as u64 * 4).max(4))?;
        ctx.upload(&mut morph_start, 0, &start)?;
        if !deltas.is_empty() {
            ctx.upload(&mut morph_deltas, 0, &deltas)?;
            ctx.upload(&mut morph_weights, 0, &m.defaults())?;
        }
        ctx.upload(&mut rest_pos, 0, &pos)?;
        ctx.upload(&mut rest_nrm, 0, &nrm)?;
        ctx.upload(&mut joint_ids, 0, &ids)?;
        ctx.upload(&mut weights, 0, &ws)?;
        ctx.upload(&mut indices, 0, &mesh.indices)?;
        Ok(Self {
            joints: joints.take(),
            morph_start: morph_start.take(),
            morph_deltas: morph_deltas.take(),
            morph_weights: morph_weights.take(),
            targets,
            rest_pos: rest_pos.take(),
            rest_nrm: rest_nrm.take(),
            joint_ids: joint_ids.take(),
            weights: weights.take(),
            pos: out_pos.take(),
            nrm: out_nrm.take(),
            indices: indices.take(),
            vertices: n as u32,
            triangles: mesh.triangles() as u32,
            joint_count,
            sets,
        })
    }

    /// Record the upload of this frame's joints (then a TRANSFER_WRITE -> COMPUTE_READ
    /// barrier before the skinning pass).
    pub fn set_pose(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        joints: &[GpuJoint],
    ) -> Result<()> {
        if joints.len() != self.joint_count {
            return Err(Error::Param(format!(
                "{} joints for a mesh skinned by {}",
                joints.len(),
                self.joint_count
            )));
        }
        ctx.update(cmd, &self.joints, 0, joints);
        Ok(())
    }

    /// Record the upload of this frame's morph target weights (tracked like the joints').
    pub fn set_weights(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        weights: &[f32],
    ) -> Result<()> {
        if weights.len() != self.targets {
            return Err(Error::Param(format!(
                "{} morph weights for a mesh with {} targets",
                weights.len(),
                self.targets
            )));
        }
        ctx.update(cmd, &self.morph_weights, 0, weights);
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.joints,
            &mut self.morph_start,
            &mut self.morph_deltas,
            &mut self.morph_weights,
            &mut self.rest_pos,
            &mut self.rest_nrm,
            &mut self.joint_ids,
            &mut self.weights,
            &mut self.pos,
            &mut self.nrm,
            &mut self.indices,
        ] {
            ctx.destroy_buffer(b);
        }
    }
}
crate::impl_destroy!(SkinnedMesh);

/// A character's mesh on the GPU with its skinning pass.
pub struct Skinner {
    pub pass: SkinPass,
    pub mesh: SkinnedMesh,
}

impl Skinner {
    pub fn new(ctx: &Context, ch: &super::Character, method: Skinning) -> Result<Self> {
        let pass = Guard::new(ctx, SkinPass::new(ctx, method, ch.mesh.influence_sets)?);
        let mesh = SkinnedMesh::new(ctx, &ch.mesh, ch.skeleton.joints.len())?;
        Ok(Self {
            pass: pass.take(),
            mesh,
        })
    }

    /// Record the joints' and morph weights' upload and the skinning; the caller makes
    /// `mesh.pos`/`mesh.nrm` visible to what reads them.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        joints: &[GpuJoint],
        weights: &[f32],
    ) -> Result<()> {
        self.mesh.set_pose(ctx, cmd, joints)?;
        self.mesh.set_weights(ctx, cmd, weights)?;
        self.pass.record(ctx, cmd, &self.mesh)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.mesh.destroy(ctx);
        self.pass.destroy(ctx);
    }
}
crate::impl_destroy!(Skinner);
