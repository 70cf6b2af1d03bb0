//! Emission beyond the passes: the atlas keeps parts apart, the UV emitter spreads births
//! over CesiumMan's surface more evenly than the vertex emitter, dead slots change nothing
//! for the live particles under every neighbour strategy, and emission scenes run with
//! their metrics and refusals.
mod common;
use common::asset;
use fluidform::character::{self, Character, UvPart};
use fluidform::emission::emit::{EmitGpuParams, EmitInput, EmitPass};
use fluidform::emission::emitter::EmitSource;
use fluidform::emission::layout::UvLayout;
use fluidform::emission::EmitterKind;
use fluidform::gpu::{sync, Buffer, Context, Labels};
use fluidform::kinds::{Neighbors, SortAlgo};
use fluidform::run::targets::emission::{births_per_triangle, uniformity, BUCKETS};
use fluidform::sph::SphSolver;
use glam::Vec3;

/// Rasterise `layout` of `mesh` at rest: each covered texel's (index, triangle, position).
fn raster(
    ctx: &Context,
    mesh: &fluidform::character::Mesh,
    layout: &UvLayout,
    size: [u32; 2],
) -> Vec<(u32, usize, Vec3)> {
    let src = EmitSource::new(
        ctx,
        EmitterKind::Uv,
        Some(layout.clone()),
        &mesh.positions,
        size,
    )
    .unwrap();
    let EmitSource::Uv(uv, _) = &src else {
        unreachable!()
    };
    let valid: Vec<u32> = ctx.readback(&uv.valid, 0, uv.valid_count as usize).unwrap();
    let pos: Vec<[f32; 4]> = ctx.read_all(&uv.pos[uv.current()]).unwrap();
    let out = valid
        .iter()
        .map(|&i| {
            let p = pos[i as usize];
            (i, p[3] as usize - 1, Vec3::new(p[0], p[1], p[2]))
        })
        .collect();
    let mut src = src;
    src.destroy(ctx);
    out
}

/// Every rectangle inside the unit square, at least a texel apart from the others; every
/// covered texel inside the rectangle of its triangle's part.
fn check_apart(layout: &UvLayout, texels: &[(u32, usize, Vec3)], size: [u32; 2]) {
    let texel = [1.0 / size[0] as f32, 1.0 / size[1] as f32];
    for (i, a) in layout.parts.iter().enumerate() {
        let r = a.rect;
        assert!(
            r[2] >= 0.0 && r[3] >= 0.0 && r[2] + r[0] <= 1.0 + 1e-6 && r[3] + r[1] <= 1.0 + 1e-6,
            "part {i} {r:?}"
        );
        for b in &layout.parts[i + 1..] {
            let s = b.rect;
            let apart_x =
                r[2] + r[0] + texel[0] <= s[2] + 1e-6 || s[2] + s[0] + texel[0] <= r[2] + 1e-6;
            let apart_y =
                r[3] + r[1] + texel[1] <= s[3] + 1e-6 || s[3] + s[1] + texel[1] <= r[3] + 1e-6;
            assert!(apart_x || apart_y, "parts overlap: {r:?} {s:?}");
        }
    }
    for &(i, tri, _) in texels {
        let part = layout
            .parts
            .iter()
            .find(|p| (p.first as usize..(p.first + p.count) as usize).contains(&tri))
            .expect("a part");
        let (x, y) = ((i % size[0]) as f32 + 0.5, (i / size[0]) as f32 + 0.5);
        let r = part.rect;
        let (u, v) = (x * texel[0], y * texel[1]);
        assert!(
            u >= r[2] && u <= r[2] + r[0] && v >= r[3] && v <= r[3] + r[1],
            "texel {i} of {} outside its rect {r:?}",
            part.name
        );
    }
}

#[test]
fn generated_atlas_keeps_parts_apart_at_one_scale() {
    let ctx = common::ctx();
    let size = [256, 256];
    // Generated: the walker's capsules, one part each.
    let walker = character::load("builtin:walker").unwrap();
    let caps = character::capsules::of(&walker);
    let layout = UvLayout::from_capsules(&walker.mesh, &caps, size).unwrap();
    assert!(
        layout.generated && layout.parts.len() >= 10,
        "{} parts",
        layout.parts.len()
    );
    assert_eq!(
        layout.triangles(),
        walker.mesh.triangles(),
        "every triangle once"
    );
    let texels = raster(&ctx, &walker.mesh, &layout, size);
    check_apart(&layout, &texels, size);
    // Equal-area maps at one scale: texels per square metre within 35% across the big parts.
    let area = |t: u32| {
        let k = &walker.mesh.indices[3 * t as usize..3 * t as usize + 3];
        let [a, b, c] = [0, 1, 2].map(|j| walker.mesh.positions[k[j] as usize]);
        0.5 * (b - a).cross(c - a).length()
    };
    let dens: Vec<f32> = layout
        .parts
        .iter()
        .map(|p| {
            let a: f32 = (p.first..p.first + p.count)
                .map(|l| area(layout.tri_of[l as usize]))
                .sum();
            let n = texels
                .iter()
                .filter(|t| (p.first as usize..(p.first + p.count) as usize).contains(&t.1))
                .count();
            (a, n as f32 / a)
        })
        .filter(|(a, _)| *a > 0.02)
        .map(|(_, d)| d)
        .collect();
    let (lo, hi) = dens
        .iter()
        .fold((f32::INFINITY, 0.0f32), |(l, h), d| (l.min(*d), h.max(*d)));
    assert!(
        dens.len() >= 5 && hi / lo < 1.35,
        "texel densities per part {dens:?}"
    );
    common::finish(&ctx);
}

/// Two UV sets in one file: CesiumMan and a copy 1 m to the side, both in [0,1]^2.
#[test]
fn two_uv_sets_in_one_mesh_pack_apart() {
    let ctx = common::ctx();
    let size = [256, 256];
    let ch: Character = character::load(&asset("CesiumMan.glb")).unwrap();
    let mut m = ch.mesh.clone();
    let (v, t) = (m.vertices() as u32, m.triangles() as u32);
    m.positions
        .extend(ch.mesh.positions.iter().map(|p| *p + Vec3::X));
    m.uvs.extend(ch.mesh.uvs.iter().copied());
    m.indices.extend(ch.mesh.indices.iter().map(|i| i + v));
    m.uv_parts = vec![
        UvPart {
            name: "a".into(),
            first: 0,
            count: t,
        },
        UvPart {
            name: "b".into(),
            first: t,
            count: t,
        },
    ];
    let layout = UvLayout::from_mesh(&m, size).unwrap();
    assert_eq!(layout.parts.len(), 2);
    let texels = raster(&ctx, &m, &layout, size);
    check_apart(&layout, &texels, size);
    let (lo, _) = character::check::bounds(&ch.mesh.positions);
    let (na, nb) = texels
        .iter()
        .fold((0, 0), |(a, b), (_, tri, p)| match *tri < t as usize {
            true => {
                assert!(
                    p.x < lo.x + 0.99 + 1e-3 || ch.mesh.positions.iter().any(|q| q.x > lo.x + 0.99),
                    "part a's texel at {p}"
                );
                (a + 1, b)
            }
            false => {
                assert!(p.x >= lo.x + 1.0 - 1e-3, "part b's texel at {p}");
                (a, b + 1)
            }
        });
    // The same surface at the same scale: about as many texels each.
    assert!(
        (na as f64 / nb as f64 - 1.0).abs() < 0.05,
        "{na} vs {nb} texels"
    );
    common::finish(&ctx);
}

/// Births per emitting primitive of `kind` on CesiumMan at rest: `steps` steps in which
/// every one of `slots` slots is born (a limit below the step).
fn births(
    ctx: &Context,
    ch: &Character,
    kind: EmitterKind,
    slots: u32,
    steps: u32,
) -> (Vec<u32>, Option<UvLayout>) {
    let size = [512, 512];
    let layout = (kind == EmitterKind::Uv).then(|| UvLayout::from_mesh(&ch.mesh, size).unwrap());
    let mut src = EmitSource::new(ctx, kind, layout.clone(), &ch.mesh.positions, size).unwrap();
    let v4: Vec<[f32; 4]> = ch
        .mesh
        .positions
        .iter()
        .map(|p| p.extend(1.0).to_array())
        .collect();
    let buf = |name: &str, bytes: u64| ctx.storage_buffer(name, bytes).unwrap();
    let mut vb = buf("verts", v4.len() as u64 * 16);
    ctx.upload(&mut vb, 0, &v4).unwrap();
    ctx.one_shot(|cmd| {
        for _ in 0..2 {
            src.record(ctx, cmd, &mut Labels, &vb).unwrap();
        }
    })
    .unwrap();
    let mut pass = EmitPass::new(ctx, kind == EmitterKind::Uv, src.primitives()).unwrap();
    let mut bufs: Vec<Buffer> = ["pos", "vel", "vhalf", "life"]
        .iter()
        .map(|n| buf(n, slots as u64 * 16))
        .collect();
    ctx.upload(
        &mut bufs[3],
        0,
        &vec![[-1.0f32, 0.0, 0.0, 0.0]; slots as usize],
    )
    .unwrap();
    let (cur, prev, valid) = src.frames();
    for s in 0..steps {
        let p = EmitGpuParams {
            n: slots,
            sources: src.sources(),
            budget: u32::MAX,
            seed: s.wrapping_mul(0x9E37_79B9) ^ 0x1234,
            limit: 1e-4,
            dt: 1e-3,
            dtau: 0.05,
            k: 30.0,
            tau_lo: 0.0,
            tau_hi: 1.0,
            frame_dt: 1.0 / 30.0,
            jitter: 0.0,
        };
        let input = EmitInput {
            cur,
            prev,
            valid,
            sources: p.sources,
            pos: &bufs[0],
            vel: &bufs[1],
            vhalf: &bufs[2],
            life: &bufs[3],
        };
        ctx.one_shot(|cmd| {
            pass.record(ctx, cmd, &p, &input);
            ctx.barrier(cmd, sync::COMPUTE_WRITE, sync::HOST_READ);
        })
        .unwrap();
    }
    let hist: Vec<u32> = ctx.read_all(&pass.hist).unwrap();
    assert_eq!(
        hist.iter().map(|h| *h as u64).sum::<u64>(),
        slots as u64 * steps as u64,
        "every birth binned"
    );
    pass.destroy(ctx);
    src.destroy(ctx);
    ctx.destroy_buffer(&mut vb);
    for b in &mut bufs {
        ctx.destroy_buffer(b);
    }
    (hist, layout)
}

#[test]
fn uv_emitter_spreads_births_more_evenly_than_vertices() {
    let ctx = common::ctx();
    let ch = character::load(&asset("CesiumMan.glb")).unwrap();
    let mut cv = Vec::new();
    for kind in [EmitterKind::Uv, EmitterKind::Vertices] {
        let (hist, layout) = births(&ctx, &ch, kind, 65536, 8);
        let per_tri = births_per_triangle(
            &ch.mesh,
            &hist,
            layout.as_ref().map(|l| l.tri_of.as_slice()),
        );
        let total: f64 = per_tri.iter().sum();
        assert!(
            (total - 8.0 * 65536.0).abs() < 1e-3 * total,
            "births kept: {total}"
        );
        let u = uniformity(&ch.mesh, &per_tri, BUCKETS);
        eprintln!(
            "{kind:?}: CV {:.4} (Poisson {:.4}) over {} buckets",
            u.uniformity_cv, u.uniformity_cv_poisson, u.buckets
        );
        assert!(u.buckets >= BUCKETS - 1 && u.buckets <= BUCKETS + 1);
        cv.push(u.uniformity_cv);
    }
    assert!(
        cv[0] < cv[1],
        "uv CV {} should beat vertices' {}",
        cv[0],
        cv[1]
    );
    common::finish(&ctx);
}

/// The live particles of a block evolve the same with dead slots beside them (keys past
/// every cell, never visited), under every neighbour strategy.
#[test]
fn dead_slots_change_nothing_for_the_live() {
    let ctx = common::ctx();
    let scene = fluidform::scene::Scene::built_in("resting-block").unwrap();
    let mut parts = scene.particles(3);
    for (i, a) in parts.attr.iter_mut().enumerate() {
        a[0] = i as f32; // an id, to match particles across runs
    }
    let n = parts.len();
    let mut with_dead = fluidform::scene::schema::Particles {
        pos: parts.pos.clone(),
        vel: parts.vel.clone(),
        attr: parts.attr.clone(),
    };
    for k in 0..777 {
        // Dead slots scattered through the fluid.
        let p = parts.pos[k * 7 % n];
        with_dead.pos.push([p[0] + 0.003, p[1], p[2], -1.0]);
        with_dead.vel.push([0.0; 4]);
        with_dead.attr.push([-1.0; 4]);
    }
    for (nb, sort) in [
        (Neighbors::Grid, SortAlgo::Counting),
        (Neighbors::Hash, SortAlgo::Bitonic),
        (Neighbors::Morton, SortAlgo::OddEven),
    ] {
        let run = |p: &fluidform::scene::schema::Particles| {
            let mut solver = SphSolver::new(&ctx, nb, Some(sort)).unwrap();
            let mut st = solver.state(&ctx, &scene, p).unwrap();
            ctx.one_shot(|cmd| {
                for _ in 0..4 {
                    solver.record_step(&ctx, cmd, &mut Labels, &mut st).unwrap();
                }
            })
            .unwrap();
            let d = st.read(&ctx).unwrap();
            st.destroy(&ctx);
            solver.destroy(&ctx);
            let mut rows: Vec<([f32; 4], [f32; 2], f32)> = d
                .pos
                .iter()
                .zip(&d.rho_p)
                .zip(&d.attr)
                .map(|((p, r), a)| (*p, *r, a[0]))
                .collect();
            rows.sort_by(|a, b| a.2.total_cmp(&b.2));
            rows
        };
        let (a, b) = (run(&parts), run(&with_dead));
        assert_eq!(a.len(), n);
        assert_eq!(b.len(), n, "{nb:?}: dead slots left out of the read");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.2, y.2);
            let dp = (0..3)
                .map(|k| (x.0[k] - y.0[k]).abs())
                .fold(0.0f32, f32::max);
            assert!(
                dp < 1e-5,
                "{nb:?}: particle {} moved {dp} m differently",
                x.2
            );
            assert!(
                (x.1[0] - y.1[0]).abs() < 1e-3 * x.1[0],
                "{nb:?}: density {} vs {}",
                x.1[0],
                y.1[0]
            );
        }
    }
    common::finish(&ctx);
}

#[test]
fn emission_scenes_run_with_their_metrics() {
    for (emitter, scene) in [("uv", "trail"), ("vertices", "trail")] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().to_str().unwrap();
        let o = common::fluidform(&[
            "run",
            "--scene",
            scene,
            "--frames",
            "12",
            "--particles",
            "1500",
            "--emitter",
            emitter,
            "--width",
            "96",
            "--height",
            "72",
            "--validation",
            "--quiet",
            "--out",
            out,
        ]);
        assert!(o.status.success(), "{}", common::text(&o));
        let s = common::summary(dir.path());
        let e = &s["stats"]["emission"];
        let seconds = s["stats"]["simulated_seconds"].as_f64().unwrap();
        assert_eq!(e["emitter"], emitter);
        let births = e["births"].as_f64().unwrap();
        // The rate limit (3000/s): births within one of rate x time.
        assert!(
            (births - 3000.0 * seconds).abs() <= 1.5,
            "{births} births in {seconds} s"
        );
        assert_eq!(
            e["alive_final"], s["stats"]["particles"],
            "the GPU count = the live slots read"
        );
        let (b, sf) = (
            e["birth_speed_mean"].as_f64().unwrap(),
            e["surface_speed_mean"].as_f64().unwrap(),
        );
        assert!(
            sf > 0.1 && (b - sf).abs() < 0.02 * sf,
            "transfer 1: birth speed {b} vs surface {sf}"
        );
        assert!(e["uniformity_cv"].as_f64().unwrap().is_finite());
        let csv = std::fs::read_to_string(dir.path().join("emission.csv")).unwrap();
        assert_eq!(csv.lines().count(), 13, "a row per frame");
        assert!(
            s["pass_ms"].get("sph/emit").is_some(),
            "the emit scope: {:?}",
            s["pass_ms"]
        );
    }
    // Refusals, one line each.
    for (args, want) in [
        (&["--uv-size", "0"][..], "sizes must be positive"),
        (&["--transfer=-1"][..], "--transfer must be at least 0"),
        (&["--life-limit", "0"][..], "--life-limit must be positive"),
        (&["--uv-size", "2x100000"][..], "outside 1..=8192"),
    ] {
        let mut a = vec!["run", "--scene", "trail", "--frames", "1", "--quiet"];
        a.extend_from_slice(args);
        let o = common::fluidform(&a);
        let t = common::text(&o);
        assert!(!o.status.success() && t.contains(want), "{args:?}: {t}");
    }
    let o = common::fluidform(&["run", "--scene", "demo", "--emitter", "uv", "--frames", "1"]);
    assert!(
        !o.status.success() && common::text(&o).contains("does not apply"),
        "{}",
        common::text(&o)
    );
}

#[test]
fn cesium_man_sheds_water_from_his_uv_layout() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!(
        "{}/tests/scenes/cesium_man_trail.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = common::fluidform(&[
        "run",
        "--scene",
        &scene,
        "--frames",
        "8",
        "--particles",
        "2000",
        "--width",
        "96",
        "--height",
        "72",
        "--validation",
        "--quiet",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", common::text(&o));
    let s = common::summary(dir.path());
    let e = &s["stats"]["emission"];
    assert_eq!(e["emitter"], "uv");
    assert_eq!(e["generated_uvs"], false, "CesiumMan has UVs");
    assert!(e["births"].as_u64().unwrap() > 0);
    assert!(s["stats"]["nan"] == 0 && s["stats"]["outside_domain"] == 0);
}
