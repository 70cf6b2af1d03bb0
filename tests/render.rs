//! The metaball renderer: every list gives the same image, the GPU's hits match the CPU
//! reference marcher, billboards are conservative, lists grow on overflow, golden images.
mod common;
use fluidform::config::Switches;
use fluidform::gpu::Context;
use fluidform::render::metaball::reference::{march, MarchParams};
use fluidform::render::metaball::{blob, blob_camera, FluidRenderer, MetaballSettings};
use fluidform::render::Camera;
use fluidform::render::{DensityFn, ListKind, Material};
use glam::Vec3;

const W: u32 = 96;
const H: u32 = 72;
const N: usize = 160;
const SPACING: f32 = 0.0271;

fn settings(list: ListKind, density: DensityFn, material: Material) -> MetaballSettings {
    let mut s = fluidform::settings::metaball_settings(&switches()).unwrap();
    s.list = list;
    s.density = density;
    s.material = material;
    s.width = W;
    s.height = H;
    s.depth = 2;
    s
}

fn switches() -> Switches {
    parse_switches(&[])
}

/// The switches of a command line holding only `args`.
fn parse_switches(args: &[&str]) -> Switches {
    use clap::Parser;
    #[derive(Parser)]
    struct Only {
        #[command(flatten)]
        s: Switches,
    }
    Only::parse_from(std::iter::once("t").chain(args.iter().copied())).s
}

struct Scene {
    pts: Vec<[f32; 4]>,
    cam: Camera,
}

fn scene() -> Scene {
    Scene {
        pts: blob(N, SPACING),
        cam: blob_camera(N, SPACING, W as f32 / H as f32),
    }
}

/// Pixels, per-pixel (t, normal) when asked, and the S-buffer's lists.
type Rendered = (Vec<u8>, Option<Vec<[f32; 4]>>, Option<Vec<Vec<u32>>>);

/// Render once and read back what the checks need.
fn render(ctx: &Context, s: MetaballSettings, sc: &Scene, debug: bool) -> Rendered {
    let mut centers = ctx
        .storage_buffer("centers", (sc.pts.len() * 16) as u64)
        .unwrap();
    ctx.upload(&mut centers, 0, &sc.pts).unwrap();
    let list = s.list;
    let mut r = FluidRenderer::new(ctx, s).unwrap();
    let mut b = r.buffers(ctx, sc.pts.len() as u64, 1, debug).unwrap();
    let (st, _) = r
        .render_sync(ctx, &mut b, &centers, sc.pts.len() as u32, &sc.cam, 0)
        .unwrap();
    assert_eq!(st.overflow, 0);
    assert_eq!(
        st.budget_pixels, 0,
        "rays cut short by llvmpipe's loop budget"
    );
    let px = b.pixels(0).to_vec();
    let dbg = debug.then(|| r.debug(ctx, &b).unwrap());
    let lists = (list == ListKind::Sbuffer).then(|| r.sbuffer_lists(ctx, &b).unwrap());
    b.destroy(ctx);
    r.destroy(ctx);
    ctx.destroy_buffer(&mut centers);
    (px, dbg, lists)
}

/// Fraction of pixels whose channels all differ by at most `tol`.
fn agreement(a: &[u8], b: &[u8], tol: u8) -> f64 {
    let same = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(x, y)| x.iter().zip(y.iter()).all(|(p, q)| p.abs_diff(*q) <= tol))
        .count();
    same as f64 / (a.len() / 4) as f64
}

/// Panics, writing a diff PNG, unless at least `min` of the pixels of `img` are within
/// `tol` per channel of `reference`.
fn assert_agrees(name: &str, img: &[u8], reference: &[u8], tol: u8, min: f64) {
    let a = agreement(img, reference, tol);
    if a < min {
        let p = write_diff(name, img, reference);
        panic!(
            "{name}: {:.4}% of pixels within {tol}/255 of the reference, need {}% (diff: {})",
            a * 100.0,
            min * 100.0,
            p.display()
        );
    }
}

fn write_diff(name: &str, a: &[u8], b: &[u8]) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("render-diffs");
    std::fs::create_dir_all(&dir).unwrap();
    let diff: Vec<u8> = a
        .chunks(4)
        .zip(b.chunks(4))
        .flat_map(|(x, y)| {
            let d = x
                .iter()
                .zip(y.iter())
                .take(3)
                .map(|(p, q)| p.abs_diff(*q))
                .max()
                .unwrap();
            [d.saturating_mul(8), 0, 0, 255]
        })
        .collect();
    let path = dir.join(format!("{name}-diff.png"));
    fluidform::gpu::target::save_rgba(&path, W, H, &diff).unwrap();
    fluidform::gpu::target::save_rgba(&dir.join(format!("{name}-got.png")), W, H, a).unwrap();
    path
}

#[test]
fn every_list_gives_the_same_image() {
    let ctx = common::ctx();
    let sc = scene();
    let densities = DensityFn::all().iter().copied();
    let materials = [
        Material::Phong,
        Material::Glass,
        Material::Tinted,
        Material::Gold,
        Material::Copper,
        Material::Aluminium,
    ];
    for d in densities {
        for m in materials {
            let (none, _, _) = render(&ctx, settings(ListKind::None, d, m), &sc, false);
            let lit = none.chunks(4).filter(|p| p[..3] != none[..3]).count();
            assert!(lit > 200, "{d:?}/{m:?}: the blob is not in the picture");
            for (list, sorted) in [
                (ListKind::Abuffer, false),
                (ListKind::Sbuffer, false),
                (ListKind::Sbuffer, true),
            ] {
                let mut s = settings(list, d, m);
                s.sorted = sorted;
                let name = s.list_name();
                let (img, _, _) = render(&ctx, s, &sc, false);
                assert_agrees(&format!("{d:?}-{m:?}-{name}"), &img, &none, 1, 0.999);
            }
        }
    }
    common::finish(&ctx);
}

#[test]
fn primary_hits_match_the_cpu_reference() {
    let ctx = common::ctx();
    let sc = scene();
    let centers: Vec<Vec3> = sc.pts.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    for d in DensityFn::all().iter().copied() {
        let mut s = settings(ListKind::Sbuffer, d, Material::Phong);
        s.refine = 20;
        let p = MarchParams {
            density: d,
            radius: s.radius,
            threshold: s.threshold,
            step: s.step,
            max_steps: s.max_steps,
            refine: 20,
        };
        let (_, dbg, _) = render(&ctx, s.clone(), &sc, true);
        let dbg = dbg.unwrap();
        let (mut checked, mut disagree) = (0, 0);
        for y in (0..H).step_by(3) {
            for x in (0..W).step_by(3) {
                let dir = sc.cam.pixel_ray(x, y, W, H);
                let cpu = march(&centers, &p, sc.cam.eye, dir);
                let g = dbg[(y * W + x) as usize];
                match (cpu, g[0] >= 0.0) {
                    (Some(h), true) => {
                        checked += 1;
                        assert!(
                            (h.t - g[0]).abs() < 2e-3,
                            "{d:?} pixel ({x}, {y}): t {} vs CPU {}",
                            g[0],
                            h.t
                        );
                        let n = Vec3::new(g[1], g[2], g[3]);
                        assert!(
                            n.dot(h.normal) > 0.995,
                            "{d:?} pixel ({x}, {y}): normal {n:?} vs CPU {:?}",
                            h.normal
                        );
                    }
                    (None, false) => {}
                    _ => disagree += 1,
                }
            }
        }
        assert!(checked > 50, "{d:?}: only {checked} hits compared");
        // Grazing rays may fall either side of a step; nearly all must agree.
        assert!(
            disagree * 100 <= checked,
            "{d:?}: {disagree} hit/miss disagreements in {checked}"
        );
    }
    common::finish(&ctx);
}

#[test]
fn billboards_are_conservative() {
    // Every sphere a pixel-centre ray meets is in that pixel's S-buffer list.
    let ctx = common::ctx();
    let sc = scene();
    let s = settings(ListKind::Sbuffer, DensityFn::Wyvill, Material::Phong);
    let r2 = s.radius * s.radius;
    let (_, _, lists) = render(&ctx, s, &sc, false);
    let lists = lists.unwrap();
    let mut hits = 0;
    for y in 0..H {
        for x in 0..W {
            let d = sc.cam.pixel_ray(x, y, W, H);
            let list = &lists[(y * W + x) as usize];
            for (j, p) in sc.pts.iter().enumerate() {
                let oc = sc.cam.eye - Vec3::new(p[0], p[1], p[2]);
                let bq = oc.dot(d);
                // Clearly hit (not grazing): the ray passes well inside the sphere.
                if bq * bq - (oc.length_squared() - r2) > 1e-3 * r2 {
                    hits += 1;
                    assert!(
                        list.contains(&(j as u32)),
                        "pixel ({x}, {y}) misses sphere {j}"
                    );
                }
            }
        }
    }
    assert!(hits > 1000);
    common::finish(&ctx);
}

#[test]
fn lists_grow_on_overflow_and_the_image_is_unchanged() {
    let ctx = common::ctx();
    let sc = scene();
    let mut centers = ctx
        .storage_buffer("centers", (sc.pts.len() * 16) as u64)
        .unwrap();
    ctx.upload(&mut centers, 0, &sc.pts).unwrap();
    let (reference, _, _) = render(
        &ctx,
        settings(ListKind::Sbuffer, DensityFn::Wyvill, Material::Phong),
        &sc,
        false,
    );
    for list in [ListKind::Abuffer, ListKind::Sbuffer] {
        let mut r =
            FluidRenderer::new(&ctx, settings(list, DensityFn::Wyvill, Material::Phong)).unwrap();
        let mut b = r
            .buffers_with_capacity(&ctx, N as u64, 1, false, 10)
            .unwrap();
        let (st, redos) = r
            .render_sync(&ctx, &mut b, &centers, N as u32, &sc.cam, 0)
            .unwrap();
        assert!(
            redos >= 1,
            "{list:?}: a 10-entry list cannot hold the frame"
        );
        assert!(st.fragments > 10 && st.overflow == 0, "{list:?}: {st:?}");
        assert!(b.list_capacity >= st.fragments, "{list:?}");
        assert!(
            agreement(b.pixels(0), &reference, 1) > 0.999,
            "{list:?}: image changed after the regrowth"
        );
        b.destroy(&ctx);
        r.destroy(&ctx);
    }
    ctx.destroy_buffer(&mut centers);
    common::finish(&ctx);
}

#[test]
fn sorted_sbuffer_ranges_are_the_unsorted_ones_in_depth_order() {
    let ctx = common::ctx();
    let sc = scene();
    let mut lists = Vec::new();
    for sorted in [false, true] {
        let mut s = settings(ListKind::Sbuffer, DensityFn::Wyvill, Material::Glass);
        s.sorted = sorted;
        assert_eq!(
            s.list_name(),
            ["sbuffer", "sbuffer-sorted"][sorted as usize]
        );
        let (_, _, l) = render(&ctx, s, &sc, false);
        lists.push(l.unwrap());
    }
    let view = sc.cam.view();
    let depth = |i: u32| {
        -view
            .transform_point3(Vec3::from_slice(&sc.pts[i as usize][..3]))
            .z
    };
    let mut long = 0;
    for (p, (unsorted, sorted)) in lists[0].iter().zip(&lists[1]).enumerate() {
        let (mut a, mut b) = (unsorted.clone(), sorted.clone());
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b, "pixel {p}: the sorted range holds other metaballs");
        assert!(
            sorted.windows(2).all(|w| depth(w[0]) <= depth(w[1]) + 1e-5),
            "pixel {p}: range not in depth order"
        );
        long += (sorted.len() > 8) as usize;
    }
    assert!(long > 100, "only {long} pixels with more than 8 metaballs");
    common::finish(&ctx);
}

#[test]
fn rays_past_llvmpipes_loop_budget_are_reported() {
    let ctx = common::ctx();
    let Some(budget) = ctx.info.loop_budget else {
        assert!(
            !ctx.info.name.contains("llvmpipe"),
            "llvmpipe has a loop budget"
        );
        eprintln!("{}: no loop budget to detect", ctx.info.name);
        common::finish(&ctx);
        return;
    };
    let sc = scene();
    let mut centers = ctx
        .storage_buffer("centers", (sc.pts.len() * 16) as u64)
        .unwrap();
    ctx.upload(&mut centers, 0, &sc.pts).unwrap();
    // A march step so fine that a ray through the blob takes about 20 000 samples, each
    // summing every metaball (several loop iterations): far past the budget. At the
    // default step no pixel is cut.
    for (step, expect_cut) in [(0.04 / 8.0, false), (0.04 / 4000.0, true)] {
        let mut s = settings(ListKind::None, DensityFn::Wyvill, Material::Phong);
        (s.width, s.height) = (24, 18);
        s.step = step;
        s.max_steps = 1 << 20;
        let mut r = FluidRenderer::new(&ctx, s).unwrap();
        let mut b = r.buffers(&ctx, N as u64, 1, false).unwrap();
        let (st, _) = r
            .render_sync(&ctx, &mut b, &centers, N as u32, &sc.cam, 0)
            .unwrap();
        assert_eq!(
            st.budget_pixels > 0,
            expect_cut,
            "step {step}: {} pixels reported past a budget of {budget}",
            st.budget_pixels
        );
        b.destroy(&ctx);
        r.destroy(&ctx);
    }
    ctx.destroy_buffer(&mut centers);
    common::finish(&ctx);
}

#[test]
fn golden_images() {
    // FLUIDFORM_UPDATE_GOLDEN=1 rewrites them (after checking the pictures by eye).
    let ctx = common::ctx();
    let sc = scene();
    for (name, m) in [
        ("phong", Material::Phong),
        ("glass", Material::Glass),
        ("gold", Material::Gold),
    ] {
        let (img, _, _) = render(
            &ctx,
            settings(ListKind::Sbuffer, DensityFn::Wyvill, m),
            &sc,
            false,
        );
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("tests/golden/blob-{name}.png"));
        if std::env::var("FLUIDFORM_UPDATE_GOLDEN").is_ok() {
            fluidform::gpu::target::save_rgba(&path, W, H, &img).unwrap();
            continue;
        }
        let golden = image::open(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .to_rgba8();
        assert_eq!(golden.dimensions(), (W, H));
        // Tolerance for other drivers' arithmetic: 99% of pixels within 4/255.
        assert_agrees(&format!("golden-{name}"), &img, golden.as_raw(), 4, 0.99);
    }
    common::finish(&ctx);
}

#[test]
fn bad_renderer_settings_are_clear_errors() {
    let ctx = common::ctx();
    let mut s = settings(ListKind::Sbuffer, DensityFn::Wyvill, Material::Phong);
    s.radius = 0.0;
    assert!(FluidRenderer::new(&ctx, s)
        .err()
        .unwrap()
        .to_string()
        .contains("--radius"));
    let mut s = settings(ListKind::Sbuffer, DensityFn::Wyvill, Material::Glass);
    s.depth = 99;
    assert!(FluidRenderer::new(&ctx, s)
        .err()
        .unwrap()
        .to_string()
        .contains("--depth"));
    let mut s = settings(ListKind::Sbuffer, DensityFn::Wyvill, Material::Phong);
    s.sky = Some("no/such/sky.png".into());
    let r = FluidRenderer::new(&ctx, s).unwrap();
    let e = r.buffers(&ctx, 10, 1, false).err().unwrap().to_string();
    assert!(e.contains("no/such/sky.png"), "{e}");
    let mut r = r;
    r.destroy(&ctx);
    // Only the S-buffer's contiguous ranges can be sorted.
    let sw = parse_switches(&["--list", "abuffer", "--list-sort", "on"]);
    let e = fluidform::settings::metaball_settings(&sw)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("--list-sort"), "{e}");
    // Glass sorts by default, Phong does not.
    let glass = parse_switches(&["--material", "glass"]);
    assert!(fluidform::settings::metaball_settings(&glass)
        .unwrap()
        .sorts_lists());
    assert!(!fluidform::settings::metaball_settings(&switches())
        .unwrap()
        .sorts_lists());
    common::finish(&ctx);
}
