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

/// Distance from `p` to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
fn tri_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).length();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).length();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).length();
    }
    let denom = 1.0 / (va + vb + vc);
    (p - (a + ab * (vb * denom) + ac * (vc * denom))).length()
}

/// Algorithm 1 on CesiumMan's surface: births capped by the budget, on the surface, with
/// the surface's velocity times the transfer rate (a rigid translation), lives in
/// (0, limit / 2); every slot accounted for across steps.
#[test]
fn emitted_particles_start_on_the_surface_with_its_velocity() {
    use fluidform::emission::emit::{EmitPass, EmitSettings};
    let ctx = common::ctx();
    let ch = character::load(&asset("CesiumMan.glb")).unwrap();
    let rest = &ch.mesh.positions;
    let (lo, hi) = character::check::bounds(rest);
    let diag = (hi - lo).length();
    let n = 4096u32;
    let frame_dt = 1.0 / 30.0;
    let settings = EmitSettings {
        limit: 2.0,
        budget: 3000,
        transfer: 1.0,
        dtau: 0.01,
    };
    for offset in [Vec3::ZERO, Vec3::new(0.1, 0.0, -0.05)] {
        let mut uv = UvSurface::new(&ctx, &ch.mesh, [128, 128]).unwrap();
        let mut emit = EmitPass::new(&ctx).unwrap();
        let buf = |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).unwrap();
        let (mut vb, mut ib) = (
            buf("verts", rest.len() as u64 * 16),
            buf("idx", ch.mesh.indices.len() as u64 * 4),
        );
        let (mut pos, mut vel, mut life) = (
            buf("pos", n as u64 * 16),
            buf("vel", n as u64 * 16),
            buf("life", n as u64 * 4),
        );
        ctx.upload(&mut ib, 0, &ch.mesh.indices).unwrap();
        ctx.upload(&mut life, 0, &vec![-1.0f32; n as usize])
            .unwrap();
        let tris = ch.mesh.indices.len() as u32 / 3;
        // Two frames: the rest pose, then the rest pose moved by `offset`.
        for d in [Vec3::ZERO, offset] {
            let v4: Vec<[f32; 4]> = rest
                .iter()
                .map(|p| (*p + d).extend(1.0).to_array())
                .collect();
            ctx.upload(&mut vb, 0, &v4).unwrap();
            ctx.one_shot(|cmd| uv.record(&ctx, cmd, &mut Labels, &vb, &ib, tris).unwrap())
                .unwrap();
        }
        let step = |k: u64, s: &EmitSettings| {
            ctx.one_shot(|cmd| {
                emit.record(
                    &ctx,
                    cmd,
                    &mut Labels,
                    &uv,
                    (&pos, &vel, &life),
                    n,
                    s,
                    (1e-3, frame_dt),
                    k,
                )
                .unwrap();
                ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::HOST_READ);
            })
            .unwrap();
            let counts: Vec<u32> = ctx.read_all(&emit.counts).unwrap();
            let l: Vec<f32> = ctx.read_all(&life).unwrap();
            (counts, l)
        };
        let (counts, l) = step(1, &settings);
        let born: Vec<usize> = (0..n as usize).filter(|i| l[*i] >= 0.0).collect();
        assert_eq!(counts[0], n, "every slot was due");
        assert_eq!(born.len(), 3000, "births capped by the budget");
        assert_eq!(counts[1], 3000, "alive = born");
        assert!(born.iter().all(|i| l[*i] < 1.0), "lives in (0, limit / 2)");
        let p: Vec<[f32; 4]> = ctx.read_all(&pos).unwrap();
        let v: Vec<[f32; 4]> = ctx.read_all(&vel).unwrap();
        let want_v = offset / frame_dt;
        for &i in &born {
            let vi = Vec3::from_slice(&v[i][..3]);
            assert!(
                (vi - want_v).length() <= 1e-3 * want_v.length().max(1.0),
                "slot {i}: velocity {vi} vs {want_v}"
            );
        }
        if offset == Vec3::ZERO {
            // On the surface: as near a triangle as float rounding allows.
            let idx = &ch.mesh.indices;
            for &i in born.iter().step_by(7) {
                let q = Vec3::from_slice(&p[i][..3]);
                let d = idx
                    .chunks(3)
                    .map(|t| {
                        tri_distance(
                            q,
                            rest[t[0] as usize],
                            rest[t[1] as usize],
                            rest[t[2] as usize],
                        )
                    })
                    .fold(f32::INFINITY, f32::min);
                assert!(d < 1e-4 * diag, "slot {i} at {q}: {d} m off the surface");
            }
            // Births spread over the texels at least as well as uniform picks: those hit
            // V (1 - (1 - 1/V)^3000) distinct texels of V on average (the hash of the slot
            // index collides a little less, which spreads births more evenly).
            let distinct: HashSet<[u32; 3]> = born
                .iter()
                .map(|i| [p[*i][0].to_bits(), p[*i][1].to_bits(), p[*i][2].to_bits()])
                .collect();
            let v = uv.valid_count as f64;
            let expected = v * (1.0 - (1.0 - 1.0 / v).powi(3000));
            assert!(
                distinct.len() as f64 > 0.95 * expected,
                "{} distinct birth texels, {expected:.0} expected of {v} texels",
                distinct.len()
            );
        }
        // The next step: the rest are born, the born age; nothing lost or duplicated.
        let (counts, l2) = step(
            2,
            &EmitSettings {
                budget: 10_000,
                ..settings
            },
        );
        assert_eq!(counts[1], n, "alive after the second step");
        assert_eq!(l2.iter().filter(|x| **x >= 0.0).count() as u32, counts[1]);
        for &i in &born {
            assert!(
                (l2[i] - (l[i] + 1e-3)).abs() < 1e-6,
                "slot {i} aged by the step"
            );
        }
        uv.destroy(&ctx);
        emit.destroy(&ctx);
        for b in [&mut vb, &mut ib, &mut pos, &mut vel, &mut life] {
            ctx.destroy_buffer(b);
        }
    }
    common::finish(&ctx);
}
