//! `bench render`: the thesis's rendering tables. A resting blob of N particles (2048 by
//! default) at 512x512, every axis the tables vary from the switches: --list (every list
//! mode and build when unset: none, A-buffer, S-buffer unsorted and sorted built by raster
//! and by compute, tiles), --build, --tile, --march, --material, --density, --threshold, --radius, --refine, --depth; or
//! --surface screen-space|mesh (one row, no lists) on the same blob.
use super::floor::Floor;
use super::protocol::{self, Case};
use super::{BenchOptions, Row};
use crate::error::Result;
use crate::gpu::Open;
use crate::gpu::{Context, Guard};
use crate::render::metaball::{blob, blob_camera, FluidRenderer};
use crate::render::{BuildKind, ListKind, SurfaceKind};
use crate::sph::FluidParams;
use serde_json::json;

pub fn render(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let other = opts
        .switches
        .metaball
        .surface
        .filter(|&k| k != SurfaceKind::Metaballs);
    let mut rows = Vec::new();
    for (list, sorted, build) in rows_of(&opts.switches)? {
        let mut settings = crate::settings::metaball_settings(&opts.switches)?;
        (settings.list, settings.sorted, settings.build) = (list, sorted, build);
        let name = match other {
            Some(k) => k.as_str(),
            None => settings.list_name(),
        };
        rows.push((settings, name));
    }
    time_rows(ctx, opts, rows)
}

/// Time the blob with each (settings, row name) together under the protocol.
pub fn time_rows(
    ctx: &Context,
    opts: &BenchOptions,
    rows: Vec<(crate::render::metaball::MetaballSettings, String)>,
) -> Result<Vec<Row>> {
    let sw = &opts.switches;
    let n = sw.common.particles.unwrap_or(2048) as usize;
    let spacing = FluidParams::default().spacing();
    let pts = blob(n, spacing);
    let mut centers = Guard::new(
        ctx,
        ctx.storage_buffer("metaball centers", (n * 16) as u64)?,
    );
    ctx.upload(&mut centers, 0, &pts)?;
    // The floor's rates, measured in this run (metaball rows only).
    let floor = match sw.metaball.surface.filter(|&k| k != SurfaceKind::Metaballs) {
        None => Some(Floor::measure(ctx, opts)?),
        Some(_) => None,
    };
    // Every row's renderer and buffers first, its lists sized (and redos counted).
    let mut sets = Vec::new();
    for (mut settings, name) in rows {
        settings.fluid = Some(blob_fluid(&pts, spacing));
        let cam = crate::run::common::camera_with_switches(
            blob_camera(n, spacing, settings.width as f32 / settings.height as f32),
            sw,
        );
        let r = Guard::new(ctx, FluidRenderer::new(ctx, settings.clone())?);
        let mut b = Guard::new(ctx, r.buffers(ctx, n as u64, 2, false)?);
        let sized = r.render_sync(ctx, &mut b, &centers, n as u32, &cam, 0)?;
        sets.push((settings, name, cam, r, b, sized));
    }
    let centers = &*centers;
    let cases = sets
        .iter()
        .map(|(settings, name, cam, r, b, _)| {
            let detail = json!({ "settings": settings, "particles": n, "spacing": spacing });
            let (r, b) = (&**r, &**b);
            Case::new(
                name.clone(),
                n as u64,
                crate::render::SCOPE,
                detail,
                move |prof, cmd| {
                    {
                        let mut prof = prof.open(ctx, cmd, crate::render::SCOPE.scope());
                        r.record(ctx, cmd, &mut *prof, b, centers, n as u32, cam, 0)?;
                    }
                    Ok(())
                },
            )
        })
        .collect();
    let mut rows = protocol::run(ctx, opts, cases)?;
    for (row, (settings, name, _, r, b, (st, redos))) in rows.iter_mut().zip(&sets) {
        let after = r.frame_stats(b, 0);
        let cut = after.budget_pixels.max(st.budget_pixels);
        // The march's per-ray counters of the last timed frame, per pixel.
        let per_px = after.march.per_pixel(settings.pixels());
        row.extra = vec![
            ("fps".into(), format!("{:.2}", 1000.0 / row.main.median)),
            (
                "list MB".into(),
                format!("{:.2}", st.list_bytes as f64 / 1e6),
            ),
            ("fragments".into(), st.fragments.to_string()),
            ("longest list".into(), st.longest.to_string()),
            ("steps/px".into(), format!("{:.1}", per_px.0)),
            (
                "skipped/px".into(),
                format!(
                    "{:.1}",
                    after.march.skipped as f64 / settings.pixels().max(1) as f64
                ),
            ),
            ("evals/px".into(), format!("{:.0}", per_px.1)),
            ("candidates/px".into(), format!("{:.1}", per_px.2)),
            ("serial max".into(), after.march.serial_max.to_string()),
            (
                "serial mean".into(),
                format!("{:.1}", after.march.serial_mean),
            ),
            ("redos".into(), redos.to_string()),
            (
                "overflow in timed frames".into(),
                after.overflow.to_string(),
            ),
            ("pixels past loop budget".into(), cut.to_string()),
        ];
        if let Some(f) = &floor {
            // The least traffic: the centres read, the picture written, the lists
            // written once and read once.
            let px = settings.pixels() as f64;
            let bytes = 16.0 * n as f64 + 4.0 * px + 2.0 * st.list_bytes as f64;
            let ms = f.ms(bytes, after.march.evaluations as f64);
            row.extra.push(("floor ms".into(), format!("{ms:.4}")));
            let above = row.main.median / ms.max(1e-12);
            row.extra.push(("x floor".into(), format!("{above:.1}")));
        }
        if cut > 0 {
            eprintln!(
                "warning: {name}: {cut} pixels' rays were cut short by llvmpipe's loop \
                 budget; this row understates the cost and its image is wrong"
            );
        }
    }
    Ok(rows)
}

/// The (list, sorted, build) rows: what --list, --list-sort and --build pick, or every
/// list mode (both S-buffer orders by both builds, and tiles) when --list is unset.
pub fn rows_of(sw: &crate::config::Switches) -> Result<Vec<(ListKind, bool, BuildKind)>> {
    let s = crate::settings::metaball_settings(sw)?;
    if sw
        .metaball
        .surface
        .is_some_and(|k| k != SurfaceKind::Metaballs)
    {
        return Ok(vec![(ListKind::None, false, BuildKind::Raster)]);
    }
    if sw.metaball.list.is_some() {
        return Ok(vec![(s.list, s.sorted, s.build)]);
    }
    let sorts = match sw.metaball.list_sort {
        Some(_) => vec![s.sorted],
        None => vec![false, true],
    };
    let builds = match sw.metaball.build {
        Some(b) => vec![b],
        None => vec![BuildKind::Raster, BuildKind::Compute],
    };
    let mut rows = Vec::new();
    if sw.metaball.build.is_none() {
        rows.push((ListKind::None, false, BuildKind::Raster));
        rows.push((ListKind::Abuffer, false, BuildKind::Raster));
    }
    for build in builds {
        for &sorted in &sorts {
            rows.push((ListKind::Sbuffer, sorted, build));
        }
    }
    if sw.metaball.build != Some(BuildKind::Raster) {
        rows.push((ListKind::Tiles, false, BuildKind::Compute));
    }
    Ok(rows)
}

/// The blob's fluid for the other surfaces: its spacing, the default smoothing length, its
/// bounds.
fn blob_fluid(pts: &[[f32; 4]], spacing: f32) -> crate::render::surface::SurfaceFluid {
    let mut bounds = [[f32::MAX; 3], [f32::MIN; 3]];
    for p in pts {
        for k in 0..3 {
            bounds[0][k] = bounds[0][k].min(p[k]);
            bounds[1][k] = bounds[1][k].max(p[k]);
        }
    }
    crate::render::surface::SurfaceFluid {
        spacing,
        h: FluidParams::default().h,
        bounds,
    }
}
