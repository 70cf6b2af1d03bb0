//! RenderToUV against a CPU rasterisation of CesiumMan's UV layout: the covered-texel list
//! (texel centres inside a UV triangle) and the positions written there (barycentric
//! interpolation of the surface), posed and at rest; a mesh without UVs is refused.
mod common;
use common::asset;
use fluidform::character::{self, Animator, Character};
use fluidform::config::Skinning;
use fluidform::emission::uv::UvSurface;
use fluidform::gpu::{sync, Context, Labels};
use glam::{Mat4, Vec2, Vec3};
use std::collections::HashSet;

/// Texel centre -> (triangle, barycentrics) of every UV triangle covering it; `edge`: the
/// texels whose centre lies within `eps` of some triangle's edge (either way is right).
fn cpu_raster(ch: &Character, size: [u32; 2], eps: f32) -> (Vec<Vec<(usize, Vec3)>>, HashSet<u32>) {
    let (w, h) = (size[0], size[1]);
    let mut cover = vec![Vec::new(); (w * h) as usize];
    let mut edge = HashSet::new();
    let uv = &ch.mesh.uvs;
    for (t, tri) in ch.mesh.indices.chunks(3).enumerate() {
        let [a, b, c] = [
            uv[tri[0] as usize],
            uv[tri[1] as usize],
            uv[tri[2] as usize],
        ];
        let scale = Vec2::new(w as f32, h as f32);
        let (pa, pb, pc) = (a * scale, b * scale, c * scale);
        let area = (pb - pa).perp_dot(pc - pa);
        if area == 0.0 {
            continue;
        }
        let lo = pa.min(pb).min(pc).floor().max(Vec2::ZERO);
        let hi = pa.max(pb).max(pc).ceil().min(scale);
        for y in lo.y as u32..hi.y as u32 {
            for x in lo.x as u32..hi.x as u32 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let l = Vec3::new(
                    (pc - pb).perp_dot(p - pb) / area,
                    (pa - pc).perp_dot(p - pc) / area,
                    (pb - pa).perp_dot(p - pa) / area,
                );
                // Distance in texels to the nearest edge line, signed inside.
                let d = [(pb, pc), (pc, pa), (pa, pb)]
                    .iter()
                    .map(|(u, v)| (*v - *u).perp_dot(p - *u) * area.signum() / (*v - *u).length())
                    .fold(f32::INFINITY, f32::min);
                let i = y * w + x;
                if d.abs() < eps {
                    edge.insert(i);
                }
                if d >= 0.0 {
                    cover[i as usize].push((t, l));
                }
            }
        }
    }
    (cover, edge)
}

fn run(ctx: &Context, ch: &Character, mats: &[Mat4], size: [u32; 2]) -> (Vec<u32>, Vec<[f32; 4]>) {
    let (posed, _) = ch.skinned_at(mats, Skinning::Lbs).unwrap();
    let mut uv = UvSurface::new(ctx, &ch.mesh, size).unwrap();
    let valid: Vec<u32> = ctx.readback(&uv.valid, 0, uv.valid_count as usize).unwrap();
    let v4: Vec<[f32; 4]> = posed.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
    let mut vb = ctx
        .storage_buffer("test verts", v4.len() as u64 * 16)
        .unwrap();
    let mut ib = ctx
        .storage_buffer("test indices", ch.mesh.indices.len() as u64 * 4)
        .unwrap();
    ctx.upload(&mut vb, 0, &v4).unwrap();
    ctx.upload(&mut ib, 0, &ch.mesh.indices).unwrap();
    ctx.one_shot(|cmd| {
        let tris = ch.mesh.indices.len() as u32 / 3;
        uv.record(ctx, cmd, &mut Labels, &vb, &ib, tris).unwrap();
        ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::HOST_READ);
    })
    .unwrap();
    let pos: Vec<[f32; 4]> = ctx.read_all(&uv.pos[uv.current()]).unwrap();
    uv.destroy(ctx);
    ctx.destroy_buffer(&mut vb);
    ctx.destroy_buffer(&mut ib);
    (valid, pos)
}

#[test]
fn uv_positions_match_a_cpu_rasterisation() {
    let ctx = common::ctx();
    let ch = character::load(&asset("CesiumMan.glb")).unwrap();
    let size = [256, 256];
    let (cover, edge) = cpu_raster(&ch, size, 1e-3);
    let anim = Animator {
        clip: Some(0),
        looping: true,
        placement: Mat4::IDENTITY,
    };
    for t in [None, Some(0.7)] {
        let mats = match t {
            None => ch.rest_matrices(),
            Some(t) => anim.joint_matrices(&ch, t),
        };
        let (valid, pos) = run(&ctx, &ch, &mats, size);
        let (posed, _) = ch.skinned_at(&mats, Skinning::Lbs).unwrap();
        // The list is the covered texels, each once, in texel order.
        assert!(valid.windows(2).all(|w| w[0] < w[1]), "sorted and unique");
        let got: HashSet<u32> = valid.iter().copied().collect();
        let want: HashSet<u32> = (0..cover.len() as u32)
            .filter(|i| !cover[*i as usize].is_empty())
            .collect();
        let wrong: Vec<u32> = got
            .symmetric_difference(&want)
            .filter(|i| !edge.contains(i))
            .copied()
            .collect();
        assert!(want.len() > 10_000, "{} texels covered", want.len());
        assert!(
            wrong.is_empty(),
            "{t:?}: {} texels differ off the edges: {:?}",
            wrong.len(),
            &wrong[..wrong.len().min(5)]
        );
        // Positions: the surface point of the one triangle covering the texel centre.
        let (lo, hi) = character::check::bounds(&posed);
        let diag = (hi - lo).length();
        let mut checked = 0;
        for &i in &valid {
            let c = &cover[i as usize];
            if c.len() != 1 || edge.contains(&i) {
                continue; // overlapping UV islands or an edge: either triangle is right
            }
            let (tri, l) = c[0];
            let k = &ch.mesh.indices[3 * tri..3 * tri + 3];
            let want = posed[k[0] as usize] * l.x
                + posed[k[1] as usize] * l.y
                + posed[k[2] as usize] * l.z;
            let p = pos[i as usize];
            let err = (Vec3::new(p[0], p[1], p[2]) - want).length() / diag;
            assert!(
                err < 1e-4,
                "{t:?}: texel {i}: {p:?} vs {want} ({err} of the size)"
            );
            assert_eq!(p[3], 1.0);
            checked += 1;
        }
        assert!(
            checked * 10 > valid.len() * 9,
            "{checked} of {} checked",
            valid.len()
        );
        // Uncovered texels hold w = 0.
        assert!(pos
            .iter()
            .enumerate()
            .all(|(i, p)| (p[3] == 1.0) == got.contains(&(i as u32))));
    }
    // A mesh without UVs is refused with the reason.
    let walker = character::load("builtin:walker").unwrap();
    let e = UvSurface::new(&ctx, &walker.mesh, size)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("no UVs"), "{e}");
    common::finish(&ctx);
}
