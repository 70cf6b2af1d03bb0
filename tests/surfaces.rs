//! The surfaces beside the metaballs: the GPU marching cubes against the CPU's on the same
//! grid, the screen-space splats against ray-sphere intersections computed here, and both
//! surfaces' coverage against the metaballs' (the plain variant).
mod common;
use fluidform::gpu::Context;
use fluidform::render::metaball::{blob, blob_camera, FluidRenderer, MetaballSettings};
use fluidform::render::surface::SurfaceFluid;
use fluidform::render::Camera;
use fluidform::render::{ListKind, SurfaceKind};
use glam::Vec3;

fn xyz(v: [f32; 4]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

const W: u32 = 96;
const H: u32 = 72;
const N: usize = 400;
const SPACING: f32 = 0.0271;
const H_SPH: f32 = 0.0457;

fn settings(surface: SurfaceKind) -> MetaballSettings {
    let sw = fluidform::window::flags::parse(&[]).unwrap();
    let mut s = fluidform::settings::metaball_settings(&sw).unwrap();
    s.surface = surface;
    if surface != SurfaceKind::Metaballs {
        s.list = ListKind::None;
        s.sorted = false;
    }
    s.width = W;
    s.height = H;
    let r = 0.5;
    s.fluid = Some(SurfaceFluid {
        spacing: SPACING,
        h: H_SPH,
        bounds: [[-r; 3], [r; 3]],
    });
    s
}

/// A rendered frame: the renderer and buffers stay alive for readbacks.
struct Frame {
    r: FluidRenderer,
    b: fluidform::render::metaball::MetaballBuffers,
    centers: fluidform::gpu::Buffer,
}

impl Frame {
    fn new(ctx: &Context, s: MetaballSettings, pts: &[[f32; 4]], cam: &Camera) -> Self {
        let mut centers = ctx
            .storage_buffer("centers", pts.len() as u64 * 16)
            .unwrap();
        ctx.upload(&mut centers, 0, pts).unwrap();
        let r = FluidRenderer::new(ctx, s).unwrap();
        let mut b = r.buffers(ctx, pts.len() as u64, 1, true).unwrap();
        let (st, _) = r
            .render_sync(ctx, &mut b, &centers, pts.len() as u32, cam, 0)
            .unwrap();
        assert_eq!(st.overflow, 0);
        Self { r, b, centers }
    }

    /// Per pixel: does the surface cover it?
    fn coverage(&self, ctx: &Context) -> Vec<bool> {
        match &self.b.surface {
            Some(sb) => sb
                .gbuffer(ctx)
                .unwrap()
                .iter()
                .map(|g| g[0][0] > 0.0)
                .collect(),
            None => self
                .r
                .debug(ctx, &self.b)
                .unwrap()
                .iter()
                .map(|d| d[0] >= 0.0)
                .collect(),
        }
    }

    fn destroy(mut self, ctx: &Context) {
        self.b.destroy(ctx);
        self.r.destroy(ctx);
        ctx.destroy_buffer(&mut self.centers);
    }
}

fn blob_scene() -> (Vec<[f32; 4]>, Camera) {
    (
        blob(N, SPACING),
        blob_camera(N, SPACING, W as f32 / H as f32),
    )
}

#[test]
fn gpu_marching_cubes_match_the_cpu_on_the_same_grid() {
    let ctx = common::ctx();
    let (pts, cam) = blob_scene();
    let f = Frame::new(&ctx, settings(SurfaceKind::Mesh), &pts, &cam);
    let sb = f.b.surface.as_ref().unwrap();
    let g = sb.shape;
    let p3: Vec<[f32; 3]> = pts.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let mass = SPACING.powi(3) * 1000.0;
    let dims = g.dims.map(|d| d as usize);
    let cpu = fluidform::isosurface::density_on(&p3, (H_SPH, mass, 1000.0), g.origin, g.cell, dims);
    // The density: fixed point on the GPU, f32 sums on the CPU.
    let gpu = sb.density(&ctx).unwrap();
    let worst = gpu
        .iter()
        .zip(&cpu.values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-4, "density differs by {worst}");
    // The same grid on the CPU: the same triangles (up to nodes within rounding of the
    // level), the same enclosed volume.
    let grid = fluidform::isosurface::Grid {
        values: gpu.clone(),
        ..cpu
    };
    let mesh = fluidform::isosurface::march(&grid, fluidform::render::surface::ISO);
    assert_eq!(mesh.open_edges(), 0);
    let soup = sb.soup(&ctx).unwrap();
    assert_eq!(soup.len() % 3, 0);
    assert_eq!(
        soup.len(),
        mesh.indices.len(),
        "GPU vs CPU triangle corners"
    );
    let volume: f64 = soup
        .chunks(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| xyz(t[k][0]).as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    assert!(
        (volume / mesh.volume() - 1.0).abs() < 1e-4,
        "GPU soup {volume} vs CPU mesh {}",
        mesh.volume()
    );
    // The blob's volume: N particles' cubes, within the 10% of the mesh export's test.
    let want = N as f64 * (SPACING as f64).powi(3);
    assert!((volume / want - 1.0).abs() < 0.10, "{volume} vs {want}");
    // Normals: unit, out of the blob (centred on the origin).
    for v in &soup {
        let (p, n) = (xyz(v[0]), xyz(v[1]));
        assert!((n.length() - 1.0).abs() < 1e-3, "normal {n}");
        assert!(n.dot(p) > 0.0, "normal {n} at {p} points in");
    }
    f.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn screen_space_splats_are_the_spheres_ray_hits() {
    let ctx = common::ctx();
    // Three separate particles: each pixel's nearest depth and chord, computed here.
    let pts = vec![
        [0.0, 0.0, 0.0, 0.0],
        [0.05, 0.02, -0.03, 0.0],
        [-0.04, -0.01, 0.02, 0.0],
    ];
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.05, 0.3),
        Vec3::ZERO,
        45.0,
        W as f32 / H as f32,
    );
    let s = settings(SurfaceKind::ScreenSpace);
    let fluid = s.fluid.unwrap();
    let r = fluid.splat_radius();
    let share = SPACING.powi(3) / (4.0 / 3.0 * std::f32::consts::PI * r.powi(3));
    let f = Frame::new(&ctx, s, &pts, &cam);
    let (depth, thick) = f.b.surface.as_ref().unwrap().splats(&ctx).unwrap();
    let fwd = (Vec3::ZERO - cam.eye).normalize();
    let mut hits = 0;
    for (i, (&z, &t)) in depth.iter().zip(&thick).enumerate() {
        let d = cam.pixel_ray(i as u32 % W, i as u32 / W, W, H);
        let (mut near, mut chords) = (f32::MAX, 0.0f32);
        for p in &pts {
            let oc = cam.eye - Vec3::new(p[0], p[1], p[2]);
            let (bb, c) = (oc.dot(d), oc.length_squared() - r * r);
            let disc = bb * bb - c;
            if disc > 0.0 {
                let s = disc.sqrt();
                near = near.min((-bb - s) * d.dot(fwd));
                chords += 2.0 * s * share;
            }
        }
        // Pixels whose ray grazes a sphere within rounding are left out.
        if near == f32::MAX {
            assert!(
                z == 0.0 || t < 1e-3,
                "pixel {i}: splat {z} where no sphere is"
            );
            continue;
        }
        hits += 1;
        assert!((z - near).abs() < 1e-4, "pixel {i}: depth {z} vs {near}");
        assert!(
            (t - chords).abs() < 2e-4 + 1e-3 * chords,
            "pixel {i}: {t} vs {chords}"
        );
    }
    eprintln!("{hits} pixels hit");
    assert!(hits > 100, "only {hits} pixels hit");
    f.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn every_surface_covers_what_the_metaballs_cover() {
    let ctx = common::ctx();
    let (pts, cam) = blob_scene();
    let plain = Frame::new(&ctx, settings(SurfaceKind::Metaballs), &pts, &cam);
    let want = plain.coverage(&ctx);
    plain.destroy(&ctx);
    let area = want.iter().filter(|&&c| c).count();
    assert!(area > 500, "the metaballs cover {area} pixels");
    for kind in [SurfaceKind::ScreenSpace, SurfaceKind::Mesh] {
        let f = Frame::new(&ctx, settings(kind), &pts, &cam);
        let got = f.coverage(&ctx);
        let both = want.iter().zip(&got).filter(|(a, b)| **a && **b).count();
        let either = want.iter().zip(&got).filter(|(a, b)| **a || **b).count();
        let iou = both as f64 / either as f64;
        eprintln!("{kind:?}: coverage IoU {iou:.3} with the metaballs'");
        assert!(
            iou > 0.85,
            "{kind:?}: coverage IoU {iou:.3} with the metaballs'"
        );
        // Every covered pixel has a unit normal facing the eye.
        let g = f.b.surface.as_ref().unwrap().gbuffer(&ctx).unwrap();
        for px in g.iter().filter(|g| g[0][0] > 0.0) {
            let n = Vec3::new(px[0][1], px[0][2], px[0][3]);
            assert!((n.length() - 1.0).abs() < 1e-3, "{kind:?}: normal {n}");
            assert!(px[1][0] >= 0.0, "{kind:?}: thickness {}", px[1][0]);
        }
        f.destroy(&ctx);
    }
    common::finish(&ctx);
}

#[test]
fn an_overflowing_soup_grows_and_the_frame_is_redone() {
    let ctx = common::ctx();
    let (pts, cam) = blob_scene();
    let mut centers = ctx
        .storage_buffer("centers", pts.len() as u64 * 16)
        .unwrap();
    ctx.upload(&mut centers, 0, &pts).unwrap();
    let r = FluidRenderer::new(&ctx, settings(SurfaceKind::Mesh)).unwrap();
    let mut b = r.buffers(&ctx, pts.len() as u64, 1, false).unwrap();
    // Room for 10 triangles: the frame overflows, the soup grows to fit and it is redone.
    b.surface.as_mut().unwrap().capacity = 30;
    let (st, redos) = r
        .render_sync(&ctx, &mut b, &centers, pts.len() as u32, &cam, 0)
        .unwrap();
    assert!(redos >= 1, "no redo");
    assert_eq!(st.overflow, 0);
    let sb = b.surface.as_ref().unwrap();
    assert!(
        sb.capacity >= 3 * st.triangles,
        "{} < 3 x {}",
        sb.capacity,
        st.triangles
    );
    assert_eq!(sb.soup(&ctx).unwrap().len() as u64, 3 * st.triangles);
    assert!(st.triangles > 100, "{} triangles", st.triangles);
    b.destroy(&ctx);
    let mut r = r;
    r.destroy(&ctx);
    ctx.destroy_buffer(&mut centers);
    common::finish(&ctx);
}
