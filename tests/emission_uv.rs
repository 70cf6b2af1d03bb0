//! RenderToUV against a CPU rasterisation of CesiumMan's UV layout: the covered-texel list
//! (texel centres inside a UV triangle) and the positions written there (barycentric
//! interpolation of the surface) and triangle, posed and at rest; a mesh without UVs is
//! refused. Algorithm 1 on CesiumMan's surface.
mod common;
use common::asset;
use fluidform::character::Skinning;
use fluidform::character::{self, Animator, Character};
use fluidform::emission::layout::UvLayout;
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
    let layout = UvLayout::from_mesh(&ch.mesh, size).unwrap();
    assert_eq!(layout.parts.len(), 1);
    assert_eq!(
        layout.parts[0].rect,
        [1.0, 1.0, 0.0, 0.0],
        "one UV set fills the atlas"
    );
    let mut uv = UvSurface::new(ctx, &layout, &ch.mesh.positions, size).unwrap();
    let valid: Vec<u32> = ctx.readback(&uv.valid, 0, uv.valid_count as usize).unwrap();
    let v4: Vec<[f32; 4]> = posed.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
    let mut vb = ctx
        .storage_buffer("test verts", v4.len() as u64 * 16)
        .unwrap();
    ctx.upload(&mut vb, 0, &v4).unwrap();
    ctx.one_shot(|cmd| {
        uv.record(ctx, cmd, &mut Labels, &vb).unwrap();
        ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::HOST_READ);
    })
    .unwrap();
    let pos: Vec<[f32; 4]> = ctx.read_all(&uv.pos[uv.current()]).unwrap();
    uv.destroy(ctx);
    ctx.destroy_buffer(&mut vb);
    (valid, pos)
}

/// Triangle `g`'s signed UV area (in texels) and how far texel `i`'s centre lies inside
/// it (texels; negative: outside).
fn uv_triangle_at(ch: &Character, g: usize, i: u32) -> (f32, f32) {
    let u = [0, 1, 2].map(|k| ch.mesh.uvs[ch.mesh.indices[3 * g + k] as usize] * 256.0);
    let area = (u[1] - u[0]).perp_dot(u[2] - u[0]);
    let q = Vec2::new((i % 256) as f32 + 0.5, (i / 256) as f32 + 0.5);
    let inside = [(u[0], u[1]), (u[1], u[2]), (u[2], u[0])]
        .iter()
        .map(|(a, b)| (*b - *a).perp_dot(q - *a) * area.signum() / (*b - *a).length())
        .fold(f32::INFINITY, f32::min);
    (area, inside)
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
            // Its triangle; or one the CPU skipped: degenerate in UV (GPU snapping can
            // give a sliver a texel) or touching the centre within rounding.
            let g = p[3] as usize - 1;
            if g != tri {
                let (area, inside) = uv_triangle_at(&ch, g, i);
                assert!(
                    area.abs() < 1e-3 || inside > -0.01,
                    "texel {i}: triangle {g} (area {area}, {inside} texels out) instead of {tri}"
                );
            }
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
            .all(|(i, p)| (p[3] >= 1.0) == got.contains(&(i as u32))));
    }
    common::finish(&ctx);
}

/// A mesh without UVs is refused with the reason.
#[test]
fn a_mesh_without_uvs_is_refused() {
    let size = [256, 256];
    let walker = character::load("builtin:walker").unwrap();
    let e = UvLayout::from_mesh(&walker.mesh, size)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("no UVs"), "{e}");
}

/// Algorithm 1 on CesiumMan's surface: births capped by the budget, on the surface, with
/// the surface's velocity times the transfer rate (a rigid translation), lives in
/// (0, limit / 2); across steps every slot accounted for (alive count = live slots), due
/// slots without budget die (pos.w = -1), permanent slots never age.
/// Long because its three steps share one emit pass and its buffers; the checks of the
/// births are apart.
#[test]
fn emitted_particles_start_on_the_surface_with_its_velocity() {
    use fluidform::emission::emit::{EmitGpuParams, EmitInput, EmitPass};
    let ctx = common::ctx();
    let ch = character::load(&asset("CesiumMan.glb")).unwrap();
    let rest = &ch.mesh.positions;
    let n = 4096u32;
    let frame_dt = 1.0f32 / 30.0;
    let size = [128, 128];
    let layout = UvLayout::from_mesh(&ch.mesh, size).unwrap();
    for offset in [Vec3::ZERO, Vec3::new(0.1, 0.0, -0.05)] {
        let mut uv = UvSurface::new(&ctx, &layout, rest, size).unwrap();
        let mut emit = EmitPass::new(&ctx, true, layout.triangles() as u32).unwrap();
        let buf = |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).unwrap();
        let mut vb = buf("verts", rest.len() as u64 * 16);
        let (mut pos, mut vel, mut vhalf, mut life) = (
            buf("pos", n as u64 * 16),
            buf("vel", n as u64 * 16),
            buf("vhalf", n as u64 * 16),
            buf("life", n as u64 * 16),
        );
        // Slot 0 is permanent; the others start dead.
        let mut l0 = vec![[-1.0f32, 0.0, 0.0, 0.0]; n as usize];
        l0[0] = [0.0, 1.0, 0.0, 0.0];
        let mut p0 = vec![[0.0f32, 0.0, 0.0, -1.0]; n as usize];
        p0[0] = [0.0; 4];
        ctx.upload(&mut life, 0, &l0).unwrap();
        ctx.upload(&mut pos, 0, &p0).unwrap();
        // Two frames: the rest pose, then the rest pose moved by `offset`.
        for d in [Vec3::ZERO, offset] {
            let v4: Vec<[f32; 4]> = rest
                .iter()
                .map(|p| (*p + d).extend(1.0).to_array())
                .collect();
            ctx.upload(&mut vb, 0, &v4).unwrap();
            ctx.one_shot(|cmd| uv.record(&ctx, cmd, &mut Labels, &vb).unwrap())
                .unwrap();
        }
        let c = uv.current();
        let params = |step: u32, budget: u32, limit: f32| EmitGpuParams {
            n,
            sources: uv.valid_count,
            budget,
            seed: step.wrapping_mul(0x9E37_79B9),
            limit,
            dt: 1e-3,
            dtau: 0.01,
            k: 1.0 / frame_dt,
            tau_lo: 0.0,
            tau_hi: 1.0,
            frame_dt,
            jitter: 0.0,
        };
        let step = |p: EmitGpuParams| {
            let input = EmitInput {
                cur: &uv.pos[c],
                prev: &uv.pos[1 - c],
                valid: &uv.valid,
                sources: uv.valid_count,
                pos: &pos,
                vel: &vel,
                vhalf: &vhalf,
                life: &life,
            };
            ctx.one_shot(|cmd| {
                emit.record(&ctx, cmd, &p, &input);
                ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::HOST_READ);
            })
            .unwrap();
            let counts: Vec<u32> = ctx.read_all(&emit.counts).unwrap();
            let l: Vec<[f32; 4]> = ctx.read_all(&life).unwrap();
            let p: Vec<[f32; 4]> = ctx.read_all(&pos).unwrap();
            (counts, l, p)
        };
        let (counts, l, p) = step(params(1, 3000, 2.0));
        let born: Vec<usize> = (1..n as usize).filter(|i| l[*i][0] >= 0.0).collect();
        assert_eq!(counts[0], n - 1, "every dead slot was due");
        assert_eq!(born.len(), 3000, "births capped by the budget");
        assert_eq!(counts[1], 3001, "alive = born + the permanent slot");
        assert!(
            born.iter().all(|i| l[*i][0] < 1.0),
            "lives in (0, limit / 2)"
        );
        assert!(born.iter().all(|i| p[*i][3] == 0.0), "born slots are live");
        assert_eq!(
            l[0],
            [0.0, 1.0, 0.0, 0.0],
            "the permanent slot does not age"
        );
        let v: Vec<[f32; 4]> = ctx.read_all(&vel).unwrap();
        let vh: Vec<[f32; 4]> = ctx.read_all(&vhalf).unwrap();
        let want_v = offset / frame_dt;
        births_move_with_the_surface(&born, &v, &vh, want_v);
        let stats: Vec<u32> = ctx.read_all(&emit.stats).unwrap();
        assert_eq!(stats[0], 3000, "births this frame");
        let mean_speed = stats[1] as f32 * 0.01 / 3000.0;
        assert!(
            (mean_speed - want_v.length()).abs() < 0.01,
            "mean birth speed {mean_speed} vs {}",
            want_v.length()
        );
        let hist: Vec<u32> = ctx.read_all(&emit.hist).unwrap();
        assert_eq!(hist.iter().sum::<u32>(), 3000, "every birth binned");
        if offset == Vec3::ZERO {
            births_on_the_rest_surface(&born, &p, rest, &ch.mesh.indices, uv.valid_count);
        }
        // The next step: the rest are born, the born age; nothing lost or duplicated.
        let (counts, l2, _) = step(params(2, 10_000, 2.0));
        assert_eq!(counts[1], n, "alive after the second step");
        assert_eq!(
            l2.iter().filter(|x| x[0] >= 0.0 || x[1] > 0.5).count() as u32,
            counts[1],
            "the alive count is the sum over slots"
        );
        for &i in &born {
            assert!(
                (l2[i][0] - (l[i][0] + 1e-3)).abs() < 1e-6,
                "slot {i} aged by the step"
            );
        }
        // A limit below every age and no budget: every emitted slot dies (dead, parked
        // for the sort), the permanent one stays.
        let (counts, l3, p3) = step(params(3, 0, 1e-4));
        assert_eq!(counts[1], 1, "only the permanent slot is alive");
        assert_eq!(counts[0], n - 1, "every emitted slot was due");
        for i in 1..n as usize {
            assert!(l3[i][0] < 0.0 && p3[i][3] < 0.0, "slot {i} died");
        }
        assert_eq!(l3[0][1], 1.0);
        uv.destroy(&ctx);
        emit.destroy(&ctx);
        for b in [&mut vb, &mut pos, &mut vel, &mut vhalf, &mut life] {
            ctx.destroy_buffer(b);
        }
    }
    common::finish(&ctx);
}

/// Sampled births lie on the rest surface (triangles `indices` over `rest`) and spread
/// over the `valid_count` texels at least as well as uniform picks.
fn births_on_the_rest_surface(
    born: &[usize],
    p: &[[f32; 4]],
    rest: &[Vec3],
    indices: &[u32],
    valid_count: u32,
) {
    // On the surface: as near a triangle as float rounding allows, and near the
    // triangle the histogram binned it under.
    let idx = indices;
    let (lo, hi) = character::check::bounds(rest);
    let diag = (hi - lo).length();
    for &i in born.iter().step_by(7) {
        let q = Vec3::from_slice(&p[i][..3]);
        let d = idx
            .chunks(3)
            .map(|t| {
                common::tri_distance(
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
    let v = valid_count as f64;
    let expected = v * (1.0 - (1.0 - 1.0 / v).powi(3000));
    assert!(
        distinct.len() as f64 > 0.95 * expected,
        "{} distinct birth texels, {expected:.0} expected of {v} texels",
        distinct.len()
    );
}

/// Every birth starts with the surface's velocity `want_v`, its half-step velocity equal.
fn births_move_with_the_surface(born: &[usize], v: &[[f32; 4]], vh: &[[f32; 4]], want_v: Vec3) {
    for &i in born {
        let vi = Vec3::from_slice(&v[i][..3]);
        assert!(
            (vi - want_v).length() <= 1e-3 * want_v.length().max(1.0),
            "slot {i}: velocity {vi} vs {want_v}"
        );
        assert_eq!(v[i], vh[i], "half-step velocity starts equal");
    }
}
