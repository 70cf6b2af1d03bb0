//! `bench skin`: the skinning pass per method on a character (the built-in walker, or
//! --character FILE) and on a generated mesh of about --vertices (default 1M) vertices:
//! copies of the walker side by side, skinned by its 13 joints mid-walk.
use super::protocol::{self, Case};
use super::{BenchOptions, Row};
use crate::character::Skinning;
use crate::character::{self, skin::Skinner, Animator, Character};
use crate::error::Result;
use crate::gpu::Open;
use crate::gpu::{Context, Guard};
use glam::{Mat4, Vec3};
use serde_json::json;

/// The skinning pass's timestamp scope.
const SKIN: crate::gpu::ScopeKey = crate::gpu::ScopeKey::new("skin");

/// `copies` of `ch` side by side (one mesh, the same skeleton and weights).
pub fn tiled(ch: &Character, copies: usize) -> Character {
    let mut out = ch.clone();
    let m = &ch.mesh;
    let (lo, hi) = character::check::bounds(&m.positions);
    let step = (hi.x - lo.x) * 1.1;
    let side = (copies as f64).sqrt().ceil() as usize;
    out.mesh.positions.clear();
    out.mesh.indices.clear();
    for c in 0..copies {
        let off = Vec3::new((c % side) as f32 * step, 0.0, (c / side) as f32 * step);
        let base = out.mesh.positions.len() as u32;
        out.mesh
            .positions
            .extend(m.positions.iter().map(|p| *p + off));
        out.mesh.indices.extend(m.indices.iter().map(|i| i + base));
    }
    out.mesh.normals = repeat(&m.normals, copies);
    out.mesh.joints = repeat(&m.joints, copies);
    out.mesh.weights = repeat(&m.weights, copies);
    out.mesh.uvs = repeat(&m.uvs, copies);
    out.source = format!("{} x{copies}", ch.source);
    out.raw_vertices = out.mesh.positions.len();
    out
}

fn repeat<T: Clone>(v: &[T], copies: usize) -> Vec<T> {
    v.iter().cycle().take(copies * v.len()).cloned().collect()
}

pub fn skin(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let sw = &opts.switches;
    let methods = match sw.character.skinning {
        Some(m) => vec![m],
        None => vec![Skinning::Lbs, Skinning::Dqs],
    };
    let file = opts
        .character
        .clone()
        .unwrap_or_else(|| "builtin:walker".into());
    let ch = character::load(&file)?;
    let walker = character::load("builtin:walker")?;
    let target = opts.vertices.unwrap_or(1 << 20) as usize;
    let big = tiled(&walker, target.div_ceil(walker.mesh.vertices()).max(1));
    let mut cases = Vec::new();
    let mut moved = Vec::new();
    for (name, c) in [(file.as_str(), &ch), ("generated", &big)] {
        let anim = Animator {
            clip: (!c.clips.is_empty()).then_some(0),
            looping: true,
            placement: Mat4::IDENTITY,
        };
        for &method in &methods {
            let joints = c.gpu_joints(&anim.joint_matrices(c, 0.4), method)?;
            let weights = anim.morph_weights(c, 0.4);
            let sk = Guard::new(ctx, Skinner::new(ctx, c, method)?);
            let variant = format!("{}-{}", method.as_str(), short(name));
            let n = c.mesh.vertices() as u64;
            let detail = json!({ "mesh": c.source, "vertices": n, "joints": c.skeleton.joints.len(),
                                 "influences": 4 * c.mesh.influence_sets, "method": method.as_str() });
            // Bytes the pass moves: rest position, normal, influences (and with morph
            // targets a range per vertex and 32 per offset) in; position, normal out.
            let range = if c.mesh.morphs.deltas.is_empty() {
                0.0
            } else {
                8.0
            };
            let per = 16.0 + 16.0 + 24.0 * c.mesh.influence_sets as f64 + range + 32.0;
            let offsets = 32.0 * c.mesh.morphs.deltas.len() as f64;
            moved.push(n as f64 * per + offsets);
            cases.push(Case::new(variant, n, SKIN, detail, move |prof, cmd| {
                {
                    let _scope = prof.open(ctx, cmd, SKIN.scope());
                    sk.record(ctx, cmd, &joints, &weights)?;
                }
                Ok(())
            }));
        }
    }
    let mut rows = protocol::run(ctx, opts, cases)?;
    for (row, bytes) in rows.iter_mut().zip(moved) {
        row.extra = vec![
            ("MB moved".into(), format!("{:.1}", bytes / 1e6)),
            (
                "GB/s".into(),
                format!("{:.2}", bytes / 1e6 / row.main.median),
            ),
        ];
    }
    Ok(rows)
}

/// A file's stem (or the built-in's name) for the variant label.
fn short(name: &str) -> String {
    let s = name.strip_prefix("builtin:").unwrap_or(name);
    std::path::Path::new(s)
        .file_stem()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| s.to_string())
}
