//! `--placement rays` on the GPU against a CPU reference: the lattice points inside
//! giraffe.obj and spot.obj (generalized winding number), the union of two overlapping
//! boxes in one mesh (each point once), lattice uniformity, and overflow reporting.
mod common;
use common::asset;
use fluidform::character::{self, check};
use fluidform::control::inside::{winding_number, InsideTest};
use fluidform::control::rays::{RaysGrid, RaysPlacer, STATS_FRAGMENTS, STATS_PARTICLES};
use fluidform::gpu::{sync, Context, Labels};
use glam::Vec3;
use std::collections::HashSet;

/// Place on the GPU: the particles and the fragment total.
fn gpu_rays(
    ctx: &Context,
    pos: &[Vec3],
    idx: &[u32],
    grid: RaysGrid,
    capacity: u32,
) -> (Vec<Vec3>, u32, u32) {
    let v4: Vec<[f32; 4]> = pos.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
    let mut vb = ctx
        .storage_buffer("test verts", v4.len() as u64 * 16)
        .unwrap();
    let mut ib = ctx
        .storage_buffer("test indices", idx.len() as u64 * 4)
        .unwrap();
    ctx.upload(&mut vb, 0, &v4).unwrap();
    ctx.upload(&mut ib, 0, idx).unwrap();
    let mut r = RaysPlacer::new(ctx, grid, capacity, 1e3).unwrap();
    ctx.one_shot(|cmd| {
        r.record(ctx, cmd, &mut Labels, &vb, &ib, idx.len() as u32 / 3)
            .unwrap();
        ctx.barrier(
            cmd,
            sync::COMPUTE_WRITE | sync::TRANSFER_WRITE,
            sync::HOST_READ | sync::TRANSFER_READ,
        );
    })
    .unwrap();
    let stats: Vec<u32> = ctx.read_all(&r.stats).unwrap();
    let out: Vec<[f32; 4]> = ctx.read_all(&r.out).unwrap();
    let (frags, n) = (
        stats[STATS_FRAGMENTS as usize / 4],
        stats[STATS_PARTICLES as usize / 4],
    );
    // Unused slots keep the parking position.
    assert!(out[n.min(capacity) as usize..].iter().all(|p| p[2] == 1e3));
    let pts = out[..n.min(capacity) as usize]
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    r.destroy(ctx);
    ctx.destroy_buffer(&mut vb);
    ctx.destroy_buffer(&mut ib);
    (pts, frags, n)
}

/// Lattice cell of a placed point.
fn key(g: &RaysGrid, p: Vec3) -> [i64; 3] {
    let q = (p - Vec3::from(g.lo)) / g.spacing - 0.5;
    [q.x.round() as i64, q.y.round() as i64, q.z.round() as i64]
}

#[test]
fn rays_placement_matches_the_winding_number() {
    let ctx = common::ctx();
    for name in ["giraffe.obj", "spot.obj"] {
        let ch = character::load(&asset(name)).unwrap();
        let (pos, idx) = (&ch.mesh.positions, &ch.mesh.indices);
        let (lo, hi) = check::bounds(pos);
        let pad = 0.05 * (hi - lo);
        let spacing = (hi - lo).max_element() / 50.0;
        let grid = RaysGrid::new((lo - pad).into(), (hi + pad).into(), spacing).unwrap();
        let (pts, frags, n) = gpu_rays(&ctx, pos, idx, grid, 200_000);
        assert!(
            frags > 0 && n as usize == pts.len(),
            "{name}: {n} particles"
        );
        let got: HashSet<[i64; 3]> = pts.iter().map(|p| key(&grid, *p)).collect();
        assert_eq!(got.len(), pts.len(), "{name}: a lattice point placed twice");
        // Every placed point is a lattice point.
        for p in &pts {
            let k = key(&grid, *p);
            let q = grid.point(k[0] as u32, k[1] as u32, k[2] as u32);
            assert!(
                q.distance(*p) < 1e-4 * spacing,
                "{name}: {p} off the lattice"
            );
        }
        // The reference: the CPU inside test (signed crossings, itself checked against the
        // winding number); where it and the GPU differ, the winding number decides, and
        // points on the surface to within numerical noise may go either way.
        let test = InsideTest::new(pos, idx);
        let [w, h, d] = grid.dims;
        let (mut expected, mut unsure, mut wrong) = (0usize, 0usize, Vec::new());
        for k in 0..d {
            for j in 0..h {
                for i in 0..w {
                    let q = grid.point(i, j, k);
                    let placed = got.contains(&[i as i64, j as i64, k as i64]);
                    let cpu = test.inside(q);
                    expected += cpu as usize;
                    if placed == cpu {
                        continue;
                    }
                    let wn = winding_number(pos, idx, q);
                    if (wn - 0.5).abs() < 0.3 {
                        unsure += 1;
                    } else if placed != (wn > 0.5) {
                        wrong.push((q, wn, placed));
                    }
                }
            }
        }
        assert!(expected > 1000, "{name}: {expected} inside");
        assert!(
            unsure * 100 <= expected,
            "{name}: {unsure} points on the surface"
        );
        assert!(
            wrong.is_empty(),
            "{name}: {} of {expected} disagree: {:?}",
            wrong.len(),
            &wrong[..wrong.len().min(5)]
        );
        // Rays are the lattice: the nearest neighbour of nearly every point is one
        // spacing away (thin parts hold lone points).
        let one = pts
            .iter()
            .filter(|p| {
                let k = key(&grid, **p);
                (0..3).any(|a| {
                    [-1i64, 1].iter().any(|s| {
                        let mut m = k;
                        m[a] += s;
                        got.contains(&m)
                    })
                })
            })
            .count();
        assert!(
            one as f32 >= 0.98 * pts.len() as f32,
            "{name}: {one} of {} have a neighbour one spacing away",
            pts.len()
        );
    }
    common::finish(&ctx);
}

/// Two boxes as one mesh, outward triangles.
fn boxes(bs: &[(Vec3, Vec3)]) -> (Vec<Vec3>, Vec<u32>) {
    let (mut pos, mut idx) = (Vec::new(), Vec::new());
    for (lo, hi) in bs {
        let b = pos.len() as u32;
        for k in 0..8 {
            pos.push(Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ));
        }
        for f in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            idx.extend([b + f[0], b + f[1], b + f[2], b + f[0], b + f[2], b + f[3]]);
        }
    }
    (pos, idx)
}

#[test]
fn overlapping_parts_give_their_union_and_overflow_is_reported() {
    let ctx = common::ctx();
    let s = 0.1;
    // Box corners between lattice planes (a third of a step off), so no point is on a face.
    let a = (Vec3::new(0.13, 0.13, 0.13), Vec3::new(0.73, 0.53, 0.63));
    let b = (Vec3::new(0.43, 0.23, 0.33), Vec3::new(0.93, 0.83, 0.93));
    let (pos, idx) = boxes(&[a, b]);
    assert!(check::signed_volume(&pos, &idx) > 0.0, "outward boxes");
    let grid = RaysGrid::new([0.0; 3], [1.0; 3], s).unwrap();
    let (pts, frags, _) = gpu_rays(&ctx, &pos, &idx, grid, 10_000);
    let got: HashSet<[i64; 3]> = pts.iter().map(|p| key(&grid, *p)).collect();
    assert_eq!(got.len(), pts.len(), "a point placed twice");
    let inside = |q: Vec3, (lo, hi): (Vec3, Vec3)| q.cmpgt(lo).all() && q.cmplt(hi).all();
    let mut want = HashSet::new();
    for k in 0..10 {
        for j in 0..10 {
            for i in 0..10 {
                if inside(grid.point(i, j, k), a) || inside(grid.point(i, j, k), b) {
                    want.insert([i as i64, j as i64, k as i64]);
                }
            }
        }
    }
    assert!(want.len() > 200);
    assert_eq!(got, want, "union of the boxes");
    // Pixels covered by both boxes see four crossings.
    assert!(frags as usize > 2 * 36, "{frags} fragments");
    // Too small a capacity: the count says so and the placer reports it.
    let (_, frags, n) = gpu_rays(&ctx, &pos, &idx, grid, 100);
    assert_eq!(
        n as usize,
        want.len(),
        "the full count even when it overflows"
    );
    let r = RaysPlacer::new(&ctx, grid, 100, 1e3).unwrap();
    let e = r.check(frags, n).unwrap_err().to_string();
    assert!(e.contains("overflow the capacity 100"), "{e}");
    let mut r = r;
    r.destroy(&ctx);
    common::finish(&ctx);
}
