//! A scene's character as it plays: placed on its path, posed, skinned on the GPU each
//! frame, and its stats (stats.character).
use crate::character::Skinning;
use crate::character::{self, skin::Skinner, Animator, Character};
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Context, Guard};
use crate::render::mesh::MeshDraw;
use crate::render::ShowMesh;
use crate::scene::character::{placed_matrices, CharacterDesc};
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// `stats.character` of summary.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CharacterStats {
    pub file: String,
    pub vertices: u64,
    pub triangles: u64,
    pub joints: u64,
    pub animation: Option<String>,
    pub skinning: Skinning,
    pub show_mesh: ShowMesh,
    /// Rest height after placement (metres).
    pub height: f32,
    /// The file's parts that are open, with their counts (filled by the winding number).
    pub open_parts: Vec<String>,
    /// The surface's regions under `WANT` (3) particle spacings across at the run's
    /// spacing, thinnest first (empty without fluid).
    pub thin_parts: Vec<ThinPart>,
}

/// A region thinner than the fluid resolves well.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThinPart {
    pub region: String,
    /// Its thickness in particle spacings.
    pub spacings: f32,
}

/// A placed character skinned each frame.
pub struct SceneCharacter {
    pub ch: Character,
    pub anim: Animator,
    pub method: Skinning,
    pub speed: f32,
    pub show: ShowMesh,
    /// (waypoints, metres per second) of a path it follows.
    pub path: Option<(Vec<Vec3>, f32)>,
    skinner: Skinner,
}

impl SceneCharacter {
    pub fn new(
        ctx: &Context,
        desc: &CharacterDesc,
        method: Skinning,
        show: ShowMesh,
    ) -> Result<Self> {
        let (ch, anim) = desc.load()?;
        // Fail before the first frame on a pose the method cannot skin: every key's.
        let mut times = vec![0.0];
        if let Some(c) = anim.clip {
            times.extend(
                ch.clips[c]
                    .channels
                    .iter()
                    .flat_map(|k| k.times.iter().copied()),
            );
        }
        let held = Animator {
            looping: false,
            ..anim.clone()
        };
        for t in times {
            ch.gpu_joints(&held.joint_matrices(&ch, t), method)?;
        }
        let skinner = Guard::new(ctx, Skinner::new(ctx, &ch, method)?);
        Ok(Self {
            ch,
            anim,
            method,
            speed: desc.speed,
            show,
            path: desc.path(),
            skinner: skinner.take(),
        })
    }

    /// The placed joint matrices at scene time `t` (clip at `speed`, along the path).
    pub fn matrices(&self, t: f64) -> Vec<Mat4> {
        placed_matrices(&self.ch, &self.anim, self.speed, self.path.as_ref(), t)
    }

    /// The morph target weights at scene time `t` (the clip's time, as `matrices`).
    pub fn morph_weights(&self, t: f64) -> Vec<f32> {
        self.anim
            .morph_weights(&self.ch, (t * self.speed as f64) as f32)
    }

    /// The skinned positions (vec4 per vertex) of the last `record`.
    pub fn skinned(&self) -> &crate::gpu::Buffer {
        &self.skinner.mesh.pos
    }

    /// Record the pose at scene time `t`: joints uploaded, the `skin` pass, its output
    /// made visible to the view's vertex shader (and compute passes).
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut dyn crate::gpu::Scopes,
        t: f64,
    ) -> Result<()> {
        let mats = self.matrices(t);
        let joints = self.ch.gpu_joints(&mats, self.method)?;
        let weights = self.morph_weights(t);
        {
            let _scope = prof.open(ctx, cmd, crate::character::skin::SKIN.scope());
            self.skinner.record(ctx, cmd, &joints, &weights)?;
        }
        Ok(())
    }

    /// The skinned mesh for the view, unless it is hidden.
    pub fn draw(&self) -> Option<MeshDraw<'_>> {
        let m = &self.skinner.mesh;
        (self.show != ShowMesh::Off).then_some(MeshDraw {
            pos: &m.pos,
            nrm: &m.nrm,
            indices: &m.indices,
            triangles: m.triangles,
        })
    }

    /// The skinned mesh of the last `record`, shown or not (emitters read it).
    pub fn surface(&self) -> MeshDraw<'_> {
        let m = &self.skinner.mesh;
        MeshDraw {
            pos: &m.pos,
            nrm: &m.nrm,
            indices: &m.indices,
            triangles: m.triangles,
        }
    }

    /// The stats, with the parts thinner than three spacings at `spacing` (the fluid's).
    pub fn stats(&self, spacing: Option<f32>) -> Result<CharacterStats> {
        let rest = self.ch.rest_matrices();
        let placed: Vec<Mat4> = rest.iter().map(|m| self.anim.placement * *m).collect();
        let (p, _) = self.ch.skinned_at(&placed, Skinning::Lbs)?;
        let (lo, hi) = character::check::bounds(&p);
        Ok(CharacterStats {
            file: self.ch.source.clone(),
            vertices: self.ch.mesh.vertices() as u64,
            triangles: self.ch.mesh.triangles() as u64,
            joints: self.ch.skeleton.joints.len() as u64,
            animation: self.anim.clip.map(|c| self.ch.clips[c].name.clone()),
            skinning: self.method,
            show_mesh: self.show,
            height: hi.y - lo.y,
            open_parts: self.ch.open_parts(),
            thin_parts: match spacing {
                Some(s) => self.thin_parts(s)?,
                None => Vec::new(),
            },
        })
    }

    /// Regions under `WANT` spacings across at spacing `s` (metres), in the placed scale.
    fn thin_parts(&self, s: f32) -> Result<Vec<ThinPart>> {
        let m = glam::Mat3::from_mat4(self.anim.placement);
        let scale = m.x_axis.length();
        let regions = character::thickness::regions(&self.ch, m * (1.0 / scale.max(1e-12)))?;
        Ok((regions.into_iter())
            .map(|r| ThinPart {
                region: r.name,
                spacings: r.thickness * scale / s,
            })
            .filter(|t| t.spacings < crate::scene::fit::WANT)
            .collect())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.skinner.destroy(ctx);
    }
}
crate::impl_destroy!(SceneCharacter);
