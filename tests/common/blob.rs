//! One frame of the resting metaball blob (the march tests' scene).
use fluidform::gpu::Context;
use fluidform::render::metaball::{blob, blob_camera, FluidRenderer, FrameStats, MetaballSettings};

/// One frame of an `n`-ball blob at `spacing` with `s`: its statistics, pixels and
/// primary (t, normal) per pixel; no pixel cut short by llvmpipe's loop budget.
pub fn frame(
    ctx: &Context,
    s: &MetaballSettings,
    n: usize,
    spacing: f32,
) -> (FrameStats, Vec<u8>, Vec<[f32; 4]>) {
    let pts = blob(n, spacing);
    let cam = blob_camera(n, spacing, s.width as f32 / s.height as f32);
    frame_of(ctx, s, &pts, &cam)
}

/// One frame of the metaballs at `pts` (w < 0: hidden) seen by `cam`, as `frame`.
#[allow(dead_code)] // not every test binary renders its own scene
pub fn frame_of(
    ctx: &Context,
    s: &MetaballSettings,
    pts: &[[f32; 4]],
    cam: &fluidform::render::Camera,
) -> (FrameStats, Vec<u8>, Vec<[f32; 4]>) {
    let n = pts.len();
    let mut centers = ctx.storage_buffer("centers", (n * 16) as u64).unwrap();
    ctx.upload(&mut centers, 0, pts).unwrap();
    let mut r = FluidRenderer::new(ctx, s.clone()).unwrap();
    let mut b = r.buffers(ctx, n as u64, 1, true).unwrap();
    let (st, _) = r
        .render_sync(ctx, &mut b, &centers, n as u32, cam, 0)
        .unwrap();
    assert_eq!(st.budget_pixels, 0);
    let px = b.pixels(0).to_vec();
    let dbg = r.debug(ctx, &b).unwrap();
    b.destroy(ctx);
    r.destroy(ctx);
    ctx.destroy_buffer(&mut centers);
    (st, px, dbg)
}
