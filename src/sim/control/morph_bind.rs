//! Morph targets carried by control particles (issue 68): each particle takes the offsets of
//! the mesh's nearest point, interpolated over its triangle's corners by the point's
//! barycentric coordinates, moved into the placed rest pose the particles are bound in (a
//! particle deep in a stretching limb moves as the nearest skin does, not as one corner).
//! The skinning pass then adds the frame's weighted offsets before skinning, on the GPU and
//! in the CPU reference, so morph weights move the water as joints do (a bird's wings, a
//! face).
use crate::character::{Character, MorphDelta, Morphs, Skinning};
use crate::error::Result;
use glam::{Mat4, Vec3};

/// `points` (placed in the placed rest pose `placed_rest` at the default weights) with the
/// offsets of their nearest point of `rest_mesh` (the character's mesh in that pose; its
/// triangles binned in cells of `cell` metres), and the points less their default
/// offsets, so the default weights give them back.
/// Without targets: no offsets and the points as they are.
pub fn bind(
    ch: &Character,
    placed_rest: &[Mat4],
    rest_mesh: &[Vec3],
    points: Vec<Vec3>,
    cell: f32,
) -> Result<(Morphs, Vec<Vec3>)> {
    let targets = &ch.mesh.morphs.targets;
    if targets.is_empty() || rest_mesh.is_empty() {
        return Ok((Morphs::default(), points));
    }
    // Skinning is affine in the vertex, so a target's offset in the placed rest pose is the
    // skinned mesh with that target at weight 1 less the mesh with every weight 0.
    let zero = vec![0.0; targets.len()];
    let base = ch.skinned_with(placed_rest, &zero, Skinning::Lbs)?.0;
    let mut offsets = Vec::with_capacity(targets.len());
    for k in 0..targets.len() {
        let mut one = zero.clone();
        one[k] = 1.0;
        let moved = ch.skinned_with(placed_rest, &one, Skinning::Lbs)?.0;
        offsets.push(
            moved
                .iter()
                .zip(&base)
                .map(|(m, b)| *m - *b)
                .collect::<Vec<_>>(),
        );
    }
    let defaults = ch.mesh.morphs.defaults();
    let idx = &ch.mesh.indices;
    let surface = super::mesh_distance::SurfaceDistance::new(rest_mesh, idx, cell.max(1e-4));
    let mut m = Morphs {
        targets: targets.clone(),
        start: vec![0],
        deltas: Vec::new(),
    };
    let mut out = Vec::with_capacity(points.len());
    for p in points {
        let (_, t, bary) = surface.nearest(p).unwrap_or((0.0, 0, [1.0, 0.0, 0.0]));
        let corners = [0, 1, 2].map(|i| idx[3 * t as usize + i] as usize);
        let mut q = p;
        for (k, off) in offsets.iter().enumerate() {
            let d = (0..3).map(|i| bary[i] * off[corners[i]]).sum::<Vec3>();
            if d == Vec3::ZERO {
                continue;
            }
            m.deltas.push(MorphDelta {
                target: k as u32,
                position: d,
                normal: Vec3::ZERO,
            });
            if defaults[k] != 0.0 {
                q -= defaults[k] * d;
            }
        }
        m.start.push(m.deltas.len() as u32);
        out.push(q);
    }
    Ok((m, out))
}
