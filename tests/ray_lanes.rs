//! Rays marched by several lanes (`--ray-lanes`): the same pictures, hits and counts as
//! the serial march for every material, list and depth; the serial chains counted on the
//! GPU equal a CPU count; lane counts the device's subgroup cannot hold are refused. The
//! occupancy grid's passed-over samples keep every picture and hit.
mod common;
use fluidform::render::metaball::reference::{march_counted, ray_box, MarchParams};
use fluidform::render::metaball::{blob, blob_camera, FluidRenderer, FrameStats, MetaballSettings};
use fluidform::render::{BuildKind, Lanes, ListKind, MarchKind, Material};
use glam::Vec3;

const W: u32 = 90;
const H: u32 = 70;
const N: usize = 160;
const SPACING: f32 = 0.0271;

/// Every list, the S-buffer unsorted and sorted.
const LISTS: [(ListKind, bool); 5] = [
    (ListKind::None, false),
    (ListKind::Abuffer, false),
    (ListKind::Sbuffer, false),
    (ListKind::Sbuffer, true),
    (ListKind::Tiles, false),
];

fn settings(list: ListKind, sorted: bool, material: Material, depth: u32) -> MetaballSettings {
    let mut s = MetaballSettings::thesis();
    (s.list, s.sorted, s.material, s.depth) = (list, sorted, material, depth);
    (s.width, s.height) = (W, H);
    if list == ListKind::Tiles {
        s.build = BuildKind::Compute;
    }
    s
}

fn render(
    ctx: &fluidform::gpu::Context,
    s: &MetaballSettings,
) -> (FrameStats, Vec<u8>, Vec<[f32; 4]>) {
    common::blob::frame(ctx, s, N, SPACING)
}

/// The lane counts this device can march a ray with (beyond the serial 1).
fn lane_counts(ctx: &fluidform::gpu::Context) -> Vec<u32> {
    let held = fluidform::render::metaball::settings::ray_lanes_on(&ctx.info);
    held.into_iter().filter(|&n| n > 1).collect()
}

/// The lanes' picture against the serial one: every primary hit at the same t to the bit
/// (the samples and bisection midpoints are the serial ones), its normal within rounding
/// (the gradient's terms add in another order on lanes), and the pixels within the golden
/// tolerance (99% within 4/255).
fn same_picture(what: &str, (px, dbg): (&[u8], &[[f32; 4]]), (px0, dbg0): (&[u8], &[[f32; 4]])) {
    for (k, (a, b)) in dbg.iter().zip(dbg0).enumerate() {
        assert!(a[0] == b[0], "{what}: pixel {k}'s hit {a:?} against {b:?}");
        let n = (1..4).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max);
        assert!(n <= 1e-4, "{what}: pixel {k}'s normal {a:?} against {b:?}");
    }
    let close = px
        .chunks(4)
        .zip(px0.chunks(4))
        .filter(|(a, b)| a.iter().zip(b.iter()).all(|(x, y)| x.abs_diff(*y) <= 4))
        .count();
    assert!(
        close * 100 >= px0.len() / 4 * 99,
        "{what}: {close} pixels close"
    );
}

/// Every list (the S-buffer unsorted and sorted) with every material path at depths 0-3
/// (Phong has no depth), and the lane layouts and off-screen ends on glass: each lane
/// count's primary hits, normals, pixels and counts (rays, samples, terms, candidates,
/// longest list, off-screen samples) are the serial march's (same_picture; Phong's counts
/// exactly, a bouncing material's to 0.2%), with a shorter serial chain.
#[test]
fn ray_lanes_give_the_serial_pictures_hits_and_counts() {
    let ctx = common::ctx();
    let lanes = lane_counts(&ctx);
    assert!(!lanes.is_empty(), "lavapipe's subgroup holds 8 lanes");
    let mut cases = Vec::new();
    for (list, sorted) in LISTS {
        cases.push(settings(list, sorted, Material::Phong, 1));
        for material in [Material::Glass, Material::Tinted, Material::Gold] {
            for depth in 0..=3 {
                if material != Material::Glass && depth % 3 != 0 {
                    continue; // their stack and bounces at the ends; glass at every depth
                }
                cases.push(settings(list, sorted, material, depth));
            }
        }
    }
    let glass = settings(ListKind::Sbuffer, true, Material::Glass, 2);
    cases.push(MetaballSettings {
        lanes: Lanes::Rows,
        ..glass.clone()
    });
    cases.push(MetaballSettings {
        offscreen_end: true,
        ..glass.clone()
    });
    for base in cases {
        let (st0, px0, dbg0) = render(&ctx, &base);
        let what0 = format!(
            "{} {:?} depth {} {:?} offscreen_end {}",
            base.list_name(),
            base.material,
            base.depth,
            base.lanes,
            base.offscreen_end
        );
        assert!(
            st0.march.rays > 0 && st0.march.serial_max > 0,
            "{what0}: {st0:?}"
        );
        assert!(dbg0.iter().any(|d| d[0] >= 0.0), "{what0}: no hits");
        for &n in &lanes {
            let s = MetaballSettings {
                ray_lanes: n,
                ..base.clone()
            };
            let what = format!("{what0} ray-lanes {n}");
            let (st, px, dbg) = render(&ctx, &s);
            same_picture(&what, (&px, &dbg), (&px0, &dbg0));
            let (m, m0) = (st.march, st0.march);
            assert_eq!(
                (m.candidates, st.longest),
                (m0.candidates, st0.longest),
                "{what}"
            );
            if base.material == Material::Phong {
                // The normal shades and sends no ray: every count is the serial one.
                assert_eq!(
                    (m.rays, m.steps, m.evaluations),
                    (m0.rays, m0.steps, m0.evaluations),
                    "{what}: counts differ"
                );
            } else {
                // A bounce from a normal a rounding apart can take another branch.
                for (a, b) in [
                    (m.rays, m0.rays),
                    (m.steps, m0.steps),
                    (m.evaluations, m0.evaluations),
                ] {
                    assert!(a.abs_diff(b) <= b / 500, "{what}: {m:?} against {m0:?}");
                }
                let (o, o0) = (st.offscreen_samples, st0.offscreen_samples);
                assert!(
                    o.abs_diff(o0) <= o0 / 100 + 8,
                    "{what}: off screen {o} against {o0}"
                );
            }
            assert!(m.serial_max < m0.serial_max, "{what}: {m:?} against {m0:?}");
        }
    }
    common::finish(&ctx);
}

/// The Lipschitz march on lanes: the serial Lipschitz march's hits and pictures (the
/// first grid sample across T is the same; the bound proves the skipped ones), from a
/// shorter chain.
#[test]
fn ray_lanes_keep_the_lipschitz_hits() {
    let ctx = common::ctx();
    for (list, sorted, material) in [
        (ListKind::None, false, Material::Phong),
        (ListKind::None, false, Material::Glass),
        (ListKind::Abuffer, false, Material::Phong),
        (ListKind::Sbuffer, true, Material::Glass),
        (ListKind::Tiles, false, Material::Phong),
    ] {
        let base = MetaballSettings {
            march: MarchKind::Lipschitz,
            ..settings(list, sorted, material, 2)
        };
        let (st0, px0, dbg0) = render(&ctx, &base);
        for n in lane_counts(&ctx) {
            let s = MetaballSettings {
                ray_lanes: n,
                ..base.clone()
            };
            let what = format!("{} {material:?} lipschitz ray-lanes {n}", s.list_name());
            let (st, px, dbg) = render(&ctx, &s);
            same_picture(&what, (&px, &dbg), (&px0, &dbg0));
            assert_eq!(st.march.candidates, st0.march.candidates, "{what}");
            assert!(
                st.march.serial_max < st0.march.serial_max,
                "{what}: {:?} against {:?}",
                st.march,
                st0.march
            );
        }
    }
    common::finish(&ctx);
}

/// The field evaluations lane `j` of a ray's `lanes` makes in series, as the CPU counts
/// them: a ray whose march ends at grid sample `samples` (of `total` in its box) takes
/// them `lanes` a round (lane j the j-th of each, while in the box: past the crossing in
/// its last round too), its bisection's `refine` midpoints L levels a round (lane j the
/// midpoint j + 1 of the round's tree: 2^L - 1 of them), and every lane the hit's gradient.
fn lane_chain(samples: u32, total: u32, hit: bool, refine: u32, lanes: u32, j: u32) -> u32 {
    let levels = (lanes + 1).ilog2();
    let mut bisect = 0;
    let mut k = 0;
    while hit && k < refine {
        let r = levels.min(refine - k);
        bisect += ((j + 1).ilog2() < r) as u32;
        k += r;
    }
    let rounds = samples.div_ceil(lanes);
    let marched = (0..rounds).filter(|r| r * lanes + j < total).count() as u32;
    marched + bisect + hit as u32
}

/// Samples one invocation evaluates in one pass over the metaballs without lists
/// (march.comp's BLOCK).
const BLOCK: u32 = 4;

/// Phong without lists (every ray marches the blob's box on the CPU reference's grid):
/// the longest serial chain and the mean over the invocations (lanes) that evaluate equal
/// the CPU's count, serial (its samples a block at a time) and on each lane count.
#[test]
fn serial_chains_match_a_cpu_count() {
    let ctx = common::ctx();
    let s = settings(ListKind::None, false, Material::Phong, 1);
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
    let rays: Vec<(u32, u32, bool)> = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .map(|(x, y)| {
            let dir = cam.pixel_ray(x, y, W, H);
            let (hit, steps) = march_counted(&centers, &p, cam.eye, dir);
            let refined = if hit.is_some() { p.refine } else { 0 };
            // The grid samples in the box, summed as the march sums them.
            let mut total = 0;
            if let Some((t0, t1)) = ray_box(cam.eye, dir, lo, hi) {
                let mut t = (t0 / p.step).ceil() * p.step;
                while t <= t1 && total < p.max_steps {
                    (t, total) = (t + p.step, total + 1);
                }
            }
            (steps - refined, total, hit.is_some())
        })
        .collect();
    for n in [1].into_iter().chain(lane_counts(&ctx)) {
        let (st, _, _) = render(
            &ctx,
            &MetaballSettings {
                ray_lanes: n,
                ..s.clone()
            },
        );
        let chains: Vec<u32> = rays
            .iter()
            .flat_map(|&(samples, total, hit)| {
                (0..n).map(move |j| match n {
                    // One invocation a ray without lists: its samples BLOCK at a time.
                    1 => samples.div_ceil(BLOCK) + if hit { p.refine + 1 } else { 0 },
                    _ => lane_chain(samples, total, hit, p.refine, n, j),
                })
            })
            .filter(|&c| c > 0)
            .collect();
        let max = *chains.iter().max().unwrap() as u64;
        let mean = chains.iter().map(|&c| c as f64).sum::<f64>() / chains.len() as f64;
        let m = st.march;
        // The GPU's box and float sums differ from the CPU's by a sample at the edges.
        assert!(
            m.serial_max.abs_diff(max) <= 1,
            "ray-lanes {n}: GPU {m:?}, CPU max {max}"
        );
        assert!(
            (m.serial_mean - mean).abs() <= 0.01 * mean,
            "ray-lanes {n}: GPU mean {} CPU {mean}",
            m.serial_mean
        );
        if n == 1 {
            // Serial: every block of samples and every hit's gradient, one after another.
            assert!(m.serial_max >= m.steps / (W * H * BLOCK) as u64);
        }
    }
    common::finish(&ctx);
}

/// A lane count wider than the device's subgroup is refused in one line naming the
/// switch and the subgroup's width; an unlisted count by the settings.
#[test]
fn ray_lanes_wider_than_the_subgroup_are_refused() {
    let ctx = common::ctx();
    let too_wide = [8, 16, 32]
        .into_iter()
        .find(|&n| n > ctx.info.subgroup_size || !ctx.info.subgroup_shuffle);
    if let Some(n) = too_wide {
        let s = MetaballSettings {
            ray_lanes: n,
            ..settings(ListKind::Sbuffer, false, Material::Phong, 1)
        };
        let e = FluidRenderer::new(&ctx, s).err().expect("refused");
        let msg = e.to_string();
        assert!(msg.contains(&format!("--ray-lanes {n}")), "{msg}");
        assert!(
            msg.contains(&format!("subgroups are {} lanes", ctx.info.subgroup_size)),
            "{msg}"
        );
        assert!(!msg.contains('\n'), "{msg}");
    }
    let s = MetaballSettings {
        ray_lanes: 4,
        ..settings(ListKind::Sbuffer, false, Material::Phong, 1)
    };
    let e = FluidRenderer::new(&ctx, s).err().expect("refused");
    assert!(
        e.to_string().contains("--ray-lanes must be 1, 8, 16 or 32"),
        "{e}"
    );
    let o = common::fluidform(&["bench", "render", "--ray-lanes", "3"]);
    assert!(!o.status.success());
    common::finish(&ctx);
}

/// Two blobs apart, with air between them and around them, and a hidden ball far off
/// that widens the fluid's bounds (hidden balls are in no sum and mark no cell).
fn two_blobs() -> (Vec<[f32; 4]>, fluidform::render::Camera) {
    let mut pts = blob(N / 2, SPACING);
    let shifted: Vec<[f32; 4]> = pts
        .iter()
        .map(|p| [p[0] + 0.3, p[1] + 0.08, p[2] - 0.2, 0.0])
        .collect();
    pts.extend(shifted);
    pts.push([-0.6, 0.5, 0.4, -1.0]);
    let cam = fluidform::render::Camera::look_at(
        Vec3::new(0.15, 0.2, 0.55),
        Vec3::new(0.15, 0.04, -0.1),
        45.0,
        W as f32 / H as f32,
    );
    (pts, cam)
}

/// `--occupancy on` (the default) against off, on two blobs with air between them: glass
/// at depth 3 on every list; Phong, tinted and gold, glass on every lane count and with
/// off-screen ends on the sorted S-buffer: the same pictures to the byte and the same hits
/// to the bit; each sample it passes over is one the full march evaluates (samples taken
/// plus passed over equal the full march's, rays and off-screen samples equal), with no
/// more terms and no longer chain; glass passes over some. Phong has no secondary ray: it
/// passes over none.
#[test]
fn occupancy_passes_over_empty_cells_with_the_same_hits() {
    let ctx = common::ctx();
    let (pts, cam) = two_blobs();
    let mut cases = Vec::new();
    for (list, sorted) in LISTS {
        cases.push(settings(list, sorted, Material::Glass, 3));
    }
    // The other paths read the grid through the same march: on one list.
    cases.push(settings(ListKind::Sbuffer, false, Material::Phong, 1));
    cases.push(settings(ListKind::Sbuffer, true, Material::Tinted, 1));
    cases.push(settings(ListKind::Sbuffer, true, Material::Gold, 2));
    let glass = settings(ListKind::Sbuffer, true, Material::Glass, 2);
    for n in lane_counts(&ctx) {
        cases.push(MetaballSettings {
            ray_lanes: n,
            ..glass.clone()
        });
    }
    cases.push(MetaballSettings {
        offscreen_end: true,
        ..glass.clone()
    });
    let mut passed_glass = 0;
    for on in cases {
        assert!(on.occupancy, "the default is on");
        let off = MetaballSettings {
            occupancy: false,
            ..on.clone()
        };
        let what = format!(
            "{} {:?} depth {} ray-lanes {} offscreen_end {}",
            on.list_name(),
            on.material,
            on.depth,
            on.ray_lanes,
            on.offscreen_end
        );
        let (st, px, dbg) = common::blob::frame_of(&ctx, &on, &pts, &cam);
        let (st0, px0, dbg0) = common::blob::frame_of(&ctx, &off, &pts, &cam);
        assert!(dbg0.iter().any(|d| d[0] >= 0.0), "{what}: no hits");
        assert!(px == px0, "{what}: the pictures differ");
        for (k, (a, b)) in dbg.iter().zip(&dbg0).enumerate() {
            assert!(
                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{what}: pixel {k}'s hit {a:?} against {b:?}"
            );
        }
        let (m, m0) = (st.march, st0.march);
        assert_eq!(m0.skipped, 0, "{what}: off passed over {m0:?}");
        assert_eq!(m.rays, m0.rays, "{what}");
        assert_eq!(
            m.steps + m.skipped,
            m0.steps,
            "{what}: {m:?} against {m0:?}"
        );
        assert_eq!(st.offscreen_samples, st0.offscreen_samples, "{what}");
        assert!(
            m.evaluations <= m0.evaluations,
            "{what}: {m:?} against {m0:?}"
        );
        assert!(
            m.serial_max <= m0.serial_max,
            "{what}: {m:?} against {m0:?}"
        );
        match on.material {
            Material::Phong => assert_eq!(m.skipped, 0, "{what}"),
            Material::Glass => {
                assert!(m.skipped > 0, "{what}: nothing passed over");
                passed_glass += 1;
            }
            _ => {}
        }
    }
    assert!(passed_glass >= 6, "{passed_glass} glass cases");
    common::finish(&ctx);
}
