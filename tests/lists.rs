//! Per-tile lists and the S-buffer built in compute: compute-built lists hold exactly the
//! raster-built lists' metaballs per pixel (and in depth order where sorted) at awkward
//! frame sizes, each tile holds its pixels' metaballs front to back, tiles give the
//! S-buffer's picture for every material and recursion depth, pairs grow on overflow, and
//! the switches that do not apply are refused.
mod common;
use fluidform::config::Switches;
use fluidform::gpu::Context;
use fluidform::render::metaball::{blob, blob_camera, FluidRenderer, MetaballSettings};
use fluidform::render::{BuildKind, ListKind, MarchKind, Material};
use std::collections::BTreeSet;

const N: usize = 160;
const SPACING: f32 = 0.0271;

fn switches(args: &[&str]) -> Switches {
    use clap::Parser;
    #[derive(Parser)]
    struct Only {
        #[command(flatten)]
        s: Switches,
    }
    Only::parse_from(std::iter::once("t").chain(args.iter().copied())).s
}

fn settings(w: u32, h: u32, list: ListKind, build: BuildKind, sorted: bool) -> MetaballSettings {
    let mut s = MetaballSettings::thesis();
    (s.width, s.height, s.list, s.build, s.sorted) = (w, h, list, build, sorted);
    s
}

struct Frame {
    pixels: Vec<u8>,
    lists: Option<Vec<Vec<u32>>>,
    tiles: Option<Vec<Vec<u32>>>,
    depths: Option<Vec<f32>>,
    redos: u32,
}

/// Render the blob once (growing what overflows) with the lists' first capacity `first`.
fn render(ctx: &Context, s: MetaballSettings, first: Option<u64>) -> Frame {
    let pts = blob(N, SPACING);
    let cam = blob_camera(N, SPACING, s.width as f32 / s.height as f32);
    let mut centers = ctx.storage_buffer("centers", (N * 16) as u64).unwrap();
    ctx.upload(&mut centers, 0, &pts).unwrap();
    let mut r = FluidRenderer::new(ctx, s.clone()).unwrap();
    let mut b = match first {
        Some(c) => r.buffers_with_capacity(ctx, N as u64, 1, false, c),
        None => r.buffers(ctx, N as u64, 1, false),
    }
    .unwrap();
    let (st, redos) = r
        .render_sync(ctx, &mut b, &centers, N as u32, &cam, 0)
        .unwrap();
    assert_eq!((st.overflow, st.budget_pixels), (0, 0), "{}", s.list_name());
    let sorted_or_tiles = s.sorts_lists() || s.bins_tiles();
    let f = Frame {
        pixels: b.pixels(0).to_vec(),
        lists: (s.list == ListKind::Sbuffer).then(|| r.sbuffer_lists(ctx, &b).unwrap()),
        tiles: s.bins_tiles().then(|| r.tile_lists(ctx, &b).unwrap()),
        depths: sorted_or_tiles.then(|| r.metaball_depths(ctx, &b, N).unwrap()),
        redos,
    };
    b.destroy(ctx);
    r.destroy(ctx);
    ctx.destroy_buffer(&mut centers);
    f
}

/// Fraction of pixels whose channels all differ by at most `tol`.
fn agreement(a: &[u8], b: &[u8], tol: u8) -> f64 {
    let same = (a.chunks(4).zip(b.chunks(4)))
        .filter(|(x, y)| x.iter().zip(y.iter()).all(|(p, q)| p.abs_diff(*q) <= tol))
        .count();
    same as f64 / (a.len() / 4) as f64
}

#[test]
fn compute_built_lists_hold_the_raster_built_ones() {
    let ctx = common::ctx();
    for (w, h) in [(1, 1), (17, 9), (513, 511)] {
        for sorted in [false, true] {
            let raster = render(
                &ctx,
                settings(w, h, ListKind::Sbuffer, BuildKind::Raster, sorted),
                None,
            );
            let s = settings(w, h, ListKind::Sbuffer, BuildKind::Compute, sorted);
            let compute = render(&ctx, s, None);
            let (rl, cl) = (raster.lists.unwrap(), compute.lists.unwrap());
            let depths = compute.depths.unwrap();
            let mut entries = 0;
            for (p, (a, b)) in rl.iter().zip(&cl).enumerate() {
                let (sa, sb): (BTreeSet<u32>, BTreeSet<u32>) =
                    (a.iter().copied().collect(), b.iter().copied().collect());
                assert_eq!(
                    sa, sb,
                    "{w}x{h} sorted={sorted}: pixel {p}'s metaballs differ"
                );
                assert_eq!(
                    a.len(),
                    b.len(),
                    "{w}x{h}: pixel {p} holds a metaball twice"
                );
                // Front to back: the compute fill's order, and the raster's after its sort
                // (the same depth sequence; ties may come in either order).
                let da: Vec<f32> = a.iter().map(|&i| depths[i as usize]).collect();
                let db: Vec<f32> = b.iter().map(|&i| depths[i as usize]).collect();
                assert!(
                    db.windows(2).all(|d| d[0] <= d[1]),
                    "{w}x{h}: pixel {p} not front to back"
                );
                if sorted {
                    assert_eq!(da, db, "{w}x{h}: pixel {p}'s depth order differs");
                }
                entries += b.len();
            }
            assert!(entries > 0, "{w}x{h}: the blob covers no pixel");
            // Each pixel's metaballs are in its tile's list, which is front to back.
            let tiles = compute.tiles.unwrap();
            let tiles_x = w.div_ceil(16) as usize;
            for (t, list) in tiles.iter().enumerate() {
                let d: Vec<f32> = list.iter().map(|&i| depths[i as usize]).collect();
                assert!(
                    d.windows(2).all(|d| d[0] <= d[1]),
                    "tile {t} not front to back"
                );
            }
            for (p, l) in cl.iter().enumerate() {
                let (x, y) = (p % w as usize, p / w as usize);
                let tile: BTreeSet<u32> =
                    tiles[(y / 16) * tiles_x + x / 16].iter().copied().collect();
                assert!(
                    l.iter().all(|i| tile.contains(i)),
                    "pixel {p}: a metaball its tile lacks"
                );
            }
        }
    }
    common::finish(&ctx);
}

#[test]
fn tiles_give_the_sbuffers_picture() {
    let ctx = common::ctx();
    let (w, h) = (96, 72);
    let cases = [
        (Material::Phong, 1, 16, MarchKind::Fixed),
        (Material::Phong, 1, 8, MarchKind::Lipschitz),
        (Material::Glass, 1, 16, MarchKind::Fixed),
        (Material::Glass, 3, 32, MarchKind::Fixed),
        (Material::Tinted, 2, 16, MarchKind::Fixed),
        (Material::Tinted, 3, 16, MarchKind::Lipschitz),
        (Material::Gold, 2, 16, MarchKind::Fixed),
        (Material::Copper, 1, 8, MarchKind::Fixed),
    ];
    for (material, depth, tile, march) in cases {
        let mut s = settings(w, h, ListKind::Sbuffer, BuildKind::Raster, false);
        (s.material, s.depth, s.march) = (material, depth, march);
        let reference = render(&ctx, s.clone(), None).pixels;
        (s.list, s.build, s.tile) = (ListKind::Tiles, BuildKind::Compute, tile);
        let tiles = render(&ctx, s.clone(), None).pixels;
        let a = agreement(&tiles, &reference, 4);
        let name = format!("{material:?} depth {depth} tile {tile} {march:?}");
        assert!(
            a >= 0.99,
            "{name}: {:.2}% of pixels within 4/255",
            a * 100.0
        );
        // The fluid is in the picture: the sky alone would agree trivially.
        let sky = render(
            &ctx,
            {
                s.threshold = 1e6;
                s
            },
            None,
        )
        .pixels;
        assert!(agreement(&tiles, &sky, 4) < 0.9, "{name}: no fluid drawn");
    }
    common::finish(&ctx);
}

#[test]
fn pairs_and_lists_grow_on_overflow_and_the_picture_is_unchanged() {
    let ctx = common::ctx();
    let tiles = settings(96, 72, ListKind::Tiles, BuildKind::Compute, false);
    let roomy = render(&ctx, tiles.clone(), None);
    let tight = render(&ctx, tiles, Some(16));
    assert!(tight.redos >= 1, "16 pairs were enough");
    assert_eq!(tight.pixels, roomy.pixels);
    // A compute-built S-buffer whose list starts at 10 entries.
    let s = settings(96, 72, ListKind::Sbuffer, BuildKind::Compute, false);
    let roomy = render(&ctx, s.clone(), None);
    let tight = render(&ctx, s, Some(10));
    assert!(tight.redos >= 1);
    assert_eq!(tight.pixels, roomy.pixels);
    common::finish(&ctx);
}

#[test]
fn switches_that_do_not_apply_are_refused() {
    let refused = [
        (
            vec!["--list", "tiles", "--tile", "7"],
            "--tile must be 8, 16 or 32",
        ),
        (
            vec!["--build", "compute", "--list", "abuffer"],
            "not --list abuffer",
        ),
        (
            vec!["--build", "compute", "--list", "none"],
            "not --list none",
        ),
        (
            vec!["--build", "raster", "--list", "tiles"],
            "built in compute",
        ),
        (
            vec!["--list", "sbuffer", "--tile", "8"],
            "--tile sets the tiles",
        ),
        (
            vec!["--list", "tiles", "--list-sort", "on"],
            "--list-sort applies",
        ),
        (
            vec!["--surface", "mesh", "--build", "compute"],
            "--build belongs",
        ),
    ];
    for (args, want) in refused {
        let e = fluidform::settings::metaball_settings(&switches(&args))
            .unwrap_err()
            .to_string();
        assert!(e.contains(want), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{args:?}: not one line: {e}");
    }
    let s = fluidform::settings::metaball_settings(&switches(&["--list", "tiles", "--tile", "32"]))
        .unwrap();
    assert_eq!(
        (s.build, s.tile, s.list_name().as_str()),
        (BuildKind::Compute, 32, "tiles-32")
    );
}

/// `run`'s default S-buffer (built in compute, sorted) draws the thesis's (raster,
/// unsorted) pictures, and is taken only where no switch asks for the thesis's build.
#[test]
fn runs_default_sbuffer_draws_the_thesis_pictures() {
    let ctx = common::ctx();
    let run = |args: &[&str]| fluidform::settings::run_metaball_settings(&switches(args), N as u32);
    let s = run(&[]).unwrap();
    assert_eq!((s.build, s.sorted), (BuildKind::Compute, true));
    let s = run(&["--build", "raster"]).unwrap();
    assert_eq!((s.build, s.sorted), (BuildKind::Raster, false));
    let s = run(&["--list-sort", "off"]).unwrap();
    assert_eq!((s.build, s.sorted), (BuildKind::Raster, false));
    assert_eq!(
        run(&["--list", "abuffer"]).unwrap().build,
        BuildKind::Raster
    );
    for (material, depth) in [
        (Material::Phong, 1),
        (Material::Tinted, 2),
        (Material::Gold, 1),
    ] {
        let mut thesis = settings(97, 71, ListKind::Sbuffer, BuildKind::Raster, false);
        (thesis.material, thesis.depth) = (material, depth);
        let mut fast = run(&[]).unwrap();
        (fast.width, fast.height, fast.material, fast.depth) = (97, 71, material, depth);
        let (a, b) = (render(&ctx, thesis, None), render(&ctx, fast, None));
        let exact = agreement(&a.pixels, &b.pixels, 0);
        let near = agreement(&a.pixels, &b.pixels, 2);
        eprintln!(
            "{material:?}: {:.3}% exact, {:.3}% within 2/255",
            exact * 100.0,
            near * 100.0
        );
        assert!(
            near >= 0.999,
            "{material:?}: {:.2}% within 2/255",
            near * 100.0
        );
    }
    common::finish(&ctx);
}

/// No switch set gives the thesis's renderer, named once (`MetaballSettings::thesis`).
#[test]
fn no_switch_gives_the_thesis_settings() {
    let s = fluidform::settings::metaball_settings(&switches(&[])).unwrap();
    assert_eq!(s, MetaballSettings::thesis());
    let tiles = fluidform::settings::metaball_settings(&switches(&["--list", "tiles"])).unwrap();
    assert_eq!(tiles.build, BuildKind::Compute);
}
