//! The march's per-ray counters (rays, samples, metaball terms, list candidates) against the
//! CPU reference marcher and against what each list holds; `--march lipschitz` against the
//! fixed march: the same hits and pictures from fewer samples.
mod common;
use fluidform::render::metaball::reference::{march_counted, ray_box, MarchParams};
use fluidform::render::metaball::{blob, blob_camera, FluidRenderer, FrameStats, MetaballSettings};
use fluidform::render::{Counters, Lanes, ListKind, MarchKind, Material};
use glam::Vec3;

const W: u32 = 96;
const H: u32 = 72;
const N: usize = 160;
const SPACING: f32 = 0.0271;

/// The blob's Phong settings with `list`.
fn settings(list: ListKind) -> MetaballSettings {
    let mut s = fluidform::render::metaball::MetaballSettings::thesis();
    s.list = list;
    s.material = Material::Phong;
    s.width = W;
    s.height = H;
    s
}

/// One frame of the blob: its statistics, pixels and primary (t, normal) per pixel.
fn render(
    ctx: &fluidform::gpu::Context,
    s: &MetaballSettings,
) -> (FrameStats, Vec<u8>, Vec<[f32; 4]>) {
    common::blob::frame(ctx, s, N, SPACING)
}

/// One Phong frame of the blob with `list`: its settings, statistics and primary hits.
fn frame(ctx: &fluidform::gpu::Context, list: ListKind) -> (MetaballSettings, FrameStats, u64) {
    let s = settings(list);
    let (st, _, dbg) = render(ctx, &s);
    let hits = dbg.iter().filter(|d| d[0] >= 0.0).count() as u64;
    (s, st, hits)
}

#[test]
fn march_counters_match_the_cpu_reference_and_the_lists() {
    let ctx = common::ctx();
    let (s, none, none_hits) = frame(&ctx, ListKind::None);
    // The CPU reference marches every pixel's ray through the same box on the same grid.
    let pts = blob(N, SPACING);
    let centers: Vec<Vec3> = pts.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    let cam = blob_camera(N, SPACING, W as f32 / H as f32);
    let p = MarchParams {
        density: s.density,
        radius: s.radius,
        threshold: s.threshold,
        step: s.step,
        max_steps: s.max_steps,
        refine: s.refine,
    };
    let lo = centers.iter().fold(Vec3::splat(f32::MAX), |a, c| a.min(*c)) - Vec3::splat(p.radius);
    let hi = centers.iter().fold(Vec3::splat(f32::MIN), |a, c| a.max(*c)) + Vec3::splat(p.radius);
    let (mut rays, mut steps, mut hits) = (0u64, 0u64, 0u64);
    for y in 0..H {
        for x in 0..W {
            let dir = cam.pixel_ray(x, y, W, H);
            if ray_box(cam.eye, dir, lo, hi).is_some() {
                rays += 1;
            }
            let (hit, k) = march_counted(&centers, &p, cam.eye, dir);
            steps += k as u64;
            hits += hit.is_some() as u64;
        }
    }
    let m = none.march;
    assert!(
        m.rays.abs_diff(rays) <= rays / 200,
        "rays: GPU {} CPU {rays}",
        m.rays
    );
    assert!(
        m.steps.abs_diff(steps) <= steps / 200,
        "steps: GPU {} CPU {steps}",
        m.steps
    );
    assert!(none_hits.abs_diff(hits) <= hits / 100 + 1);
    // none: every sample and every hit's gradient sums all N; every pixel is offered all N.
    assert_eq!(m.evaluations, (m.steps + none_hits) * N as u64);
    assert_eq!(m.candidates, (W * H) as u64 * N as u64);
    // Lists: the candidates are the list entries; they cut the terms summed, and the
    // samples to the spheres' depth interval.
    for list in [ListKind::Abuffer, ListKind::Sbuffer] {
        let (_, st, _) = frame(&ctx, list);
        assert_eq!(st.march.candidates, st.fragments, "{list:?}");
        assert!(
            st.march.steps > 0 && st.march.steps < m.steps,
            "{list:?}: {st:?}"
        );
        assert!(st.march.evaluations * 4 < m.evaluations, "{list:?}: {st:?}");
        assert!(
            st.march.rays <= m.rays && st.march.rays > 0,
            "{list:?}: {st:?}"
        );
    }
    common::finish(&ctx);
}

#[test]
fn lipschitz_march_finds_the_fixed_hits_from_fewer_samples() {
    let ctx = common::ctx();
    for (list, sorted, material) in [
        (ListKind::None, false, Material::Phong),
        (ListKind::None, false, Material::Glass),
        (ListKind::Abuffer, false, Material::Phong),
        (ListKind::Sbuffer, false, Material::Phong),
        (ListKind::Sbuffer, true, Material::Glass),
        (ListKind::Abuffer, false, Material::Tinted),
    ] {
        let mut s = settings(list);
        s.sorted = sorted;
        s.material = material;
        s.depth = 2;
        let (fixed, fixed_px, fixed_dbg) = render(&ctx, &s);
        s.march = MarchKind::Lipschitz;
        let (lip, lip_px, lip_dbg) = render(&ctx, &s);
        let name = format!("{list:?} sorted {sorted} {material:?}");
        // Hits: the same pixels, at the same t within the refined hit's error.
        let tol = 1.5 * s.step / (1u32 << s.refine) as f32 + 1e-5;
        let same = fixed_dbg
            .iter()
            .zip(&lip_dbg)
            .filter(|(a, b)| match (a[0] >= 0.0, b[0] >= 0.0) {
                (true, true) => (a[0] - b[0]).abs() <= tol,
                (false, false) => true,
                _ => false,
            })
            .count();
        let hits = fixed_dbg.iter().filter(|d| d[0] >= 0.0).count();
        assert!(hits > 500, "{name}: {hits} hits");
        assert!(
            same * 1000 >= fixed_dbg.len() * 995,
            "{name}: {same} of {} agree",
            fixed_dbg.len()
        );
        // The pictures within the golden tolerance (99% of pixels within 4/255).
        let close = fixed_px
            .chunks(4)
            .zip(lip_px.chunks(4))
            .filter(|(a, b)| a.iter().zip(b.iter()).all(|(x, y)| x.abs_diff(*y) <= 4))
            .count();
        assert!(
            close * 100 >= fixed_px.len() / 4 * 99,
            "{name}: {close} pixels close"
        );
        // Fewer samples, the same primary rays.
        assert!(
            lip.march.steps < fixed.march.steps,
            "{name}: {:?} vs {:?}",
            lip.march,
            fixed.march
        );
        assert_eq!(lip.march.candidates, fixed.march.candidates, "{name}");
    }
    common::finish(&ctx);
}

#[test]
fn march_is_refused_with_the_other_surfaces() {
    let o = common::fluidform(&[
        "bench",
        "render",
        "--surface",
        "mesh",
        "--march",
        "lipschitz",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--march belongs to the metaball surface"),
        "{err}"
    );
}

/// Every counter mode and lane layout against the defaults (counters summed per workgroup,
/// 8 x 8 blocks), per list for Phong, and for glass on the S-buffer (secondary rays read
/// other pixels' lists; off-screen samples), on a
/// frame whose sides are no multiple of 8 (blocks past its edge): the same pixels and hits
/// bit for bit, and the same counts (off: none, the longest list included).
#[test]
fn counter_modes_and_lane_layouts_give_the_same_frames_and_counts() {
    let ctx = common::ctx();
    for list in [
        ListKind::None,
        ListKind::Abuffer,
        ListKind::Sbuffer,
        ListKind::Tiles,
    ] {
        for material in [Material::Phong, Material::Glass] {
            if material == Material::Glass && list != ListKind::Sbuffer {
                continue;
            }
            let mut base = settings(list);
            (base.material, base.width, base.height) = (material, 90, 70);
            base.build = match list {
                ListKind::Tiles => fluidform::render::BuildKind::Compute,
                _ => base.build,
            };
            let (st0, px0, dbg0) = render(&ctx, &base);
            assert!(st0.march.rays > 0 && (list == ListKind::None || st0.longest > 0));
            for &counters in Counters::all() {
                for &lanes in Lanes::all() {
                    if list == ListKind::Tiles && lanes == Lanes::Rows {
                        continue;
                    }
                    let s = MetaballSettings {
                        counters,
                        lanes,
                        ..base.clone()
                    };
                    let what = format!("{list:?} {material:?} {counters:?} {lanes:?}");
                    let (st, px, dbg) = render(&ctx, &s);
                    assert!(px == px0, "{what}: pixels differ");
                    assert!(dbg == dbg0, "{what}: hits differ");
                    match counters {
                        Counters::Off => {
                            assert_eq!(st.march, Default::default(), "{what}");
                            assert_eq!((st.longest, st.offscreen_samples), (0, 0), "{what}");
                        }
                        _ => {
                            assert_eq!(st.march, st0.march, "{what}: counts differ");
                            assert_eq!(st.longest, st0.longest, "{what}");
                            assert_eq!(st.offscreen_samples, st0.offscreen_samples, "{what}");
                        }
                    }
                }
            }
        }
    }
    let bad = MetaballSettings {
        lanes: Lanes::Rows,
        build: fluidform::render::BuildKind::Compute,
        ..settings(ListKind::Tiles)
    };
    let e = FluidRenderer::new(&ctx, bad)
        .err()
        .expect("tiles with rows refused");
    assert!(e.to_string().contains("--lanes rows"), "{e}");
    common::finish(&ctx);
}
