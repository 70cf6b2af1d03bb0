//! A scene character as particle systems see it: its posed capsules (colliders of kind
//! `character`, uploaded each frame) and its skinned triangles (the `mesh` emitter, picked
//! by bind-pose area through a CDF, placed on the skinned triangle).
use crate::character::capsules::{self, BoneCapsule};
use crate::character::Character;
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::{Buffer, Context, Guard};
use crate::render::mesh::MeshDraw;
use glam::Mat4;

/// Most capsules a character collider holds (one per bone).
pub const MAX_CAPSULES: usize = 64;

/// The buffers a frame's passes read (FrameInfo::character).
#[derive(Clone, Copy)]
pub struct CharacterBufs<'a> {
    /// Skinned positions (vec4 per vertex) and triangle indices.
    pub pos: &'a Buffer,
    pub indices: &'a Buffer,
    /// Cumulative bind-pose triangle areas, normalised to end at 1.
    pub cdf: &'a Buffer,
    /// Posed capsules: vec4 (a, r), vec4 (b, 0) each.
    pub capsules: &'a Buffer,
    pub capsule_count: u32,
    pub triangles: u32,
}

pub struct CharacterLink {
    bones: Vec<BoneCapsule>,
    capsules: Buffer,
    cdf: Buffer,
    triangles: u32,
}

impl CharacterLink {
    /// For `ch` in its rest pose (capsules and the emitting triangles' areas).
    pub fn new(ctx: &Context, ch: &Character) -> Result<Self> {
        let mut bones = capsules::of(ch);
        if bones.len() > MAX_CAPSULES {
            // The largest ones collide; the rest are fingers and the like.
            bones.sort_by(|a, b| b.r.total_cmp(&a.r));
            bones.truncate(MAX_CAPSULES);
        }
        let mesh = &ch.mesh;
        let mut acc = 0.0f64;
        let mut cdf: Vec<f32> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| {
                let p = |k: usize| mesh.positions[t[k] as usize];
                acc += 0.5 * (p(1) - p(0)).cross(p(2) - p(0)).length() as f64;
                acc as f32
            })
            .collect();
        if cdf.is_empty() || acc.is_nan() || acc <= 0.0 {
            return Err(Error::Param(format!(
                "character {}: no triangle with an area to emit from",
                ch.source
            )));
        }
        for c in &mut cdf {
            *c /= acc as f32;
        }
        let capsules = Guard::new(
            ctx,
            ctx.storage_buffer("character capsules", (MAX_CAPSULES * 32) as u64)?,
        );
        let mut cdf_buf = Guard::new(
            ctx,
            ctx.storage_buffer("character triangle areas", cdf.len() as u64 * 4)?,
        );
        ctx.upload(&mut cdf_buf, 0, &cdf)?;
        Ok(Self {
            bones,
            capsules: capsules.take(),
            cdf: cdf_buf.take(),
            triangles: cdf.len() as u32,
        })
    }

    /// Record the capsules posed by the joint matrices `mats` (visible to compute after
    /// a transfer barrier).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, mats: &[Mat4]) {
        let data: Vec<[f32; 8]> = self
            .bones
            .iter()
            .map(|b| {
                let p = b.posed(mats);
                [p.a.x, p.a.y, p.a.z, p.r, p.b.x, p.b.y, p.b.z, 0.0]
            })
            .collect();
        if !data.is_empty() {
            ctx.update(cmd, &self.capsules, 0, &data);
        }
    }

    /// The buffers of the character's skinned `surface`.
    pub fn bufs<'a>(&'a self, m: MeshDraw<'a>) -> CharacterBufs<'a> {
        CharacterBufs {
            pos: m.pos,
            indices: m.indices,
            cdf: &self.cdf,
            capsules: &self.capsules,
            capsule_count: self.bones.len() as u32,
            triangles: self.triangles,
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_buffer(&mut self.capsules);
        ctx.destroy_buffer(&mut self.cdf);
    }
}
crate::impl_destroy!(CharacterLink);
