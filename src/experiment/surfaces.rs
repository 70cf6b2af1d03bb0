//! `fluidform experiment surfaces`: the three surfaces (metaballs with the S-buffer,
//! screen-space fluid, marching cubes) on the liquid character and the dam break at one
//! frame size: per-pass GPU ms, the renderer's memory and the last frame of each side by
//! side; and the marching cubes at the particle spacing against one SPH step at 64K
//! particles.
use super::findings::{Finding, Verdict};
use super::{write, Env, Experiment, Steps};
use crate::error::{Error, Result};
use crate::render::surface::cubes::{CELLS_SCOPE, DENSITY_SCOPE, RASTER_SCOPE};
use crate::render::{RenderKind, SurfaceKind};
use crate::run::RunSummary;
use std::path::{Path, PathBuf};

pub const SCREEN_FASTER: &str =
    "screen-space fluid at least 5x faster than the S-buffer metaballs (liquid character)";
pub const CUBES_CHEAP: &str =
    "marching cubes at the particle spacing cost less than one SPH step at 64K particles";

/// (label, scene, frames, frames with --quick).
const SCENES: &[(&str, &str, u64, u64)] = &[
    ("liquid character", "character", 200, 30),
    ("dam break", "dam-break", 150, 30),
];
const SURFACES: [SurfaceKind; 3] = [
    SurfaceKind::Metaballs,
    SurfaceKind::ScreenSpace,
    SurfaceKind::Mesh,
];

/// The surface, and for the mesh its cell and the particle count.
type Look = (SurfaceKind, Option<f32>, Option<u32>);

fn play(env: &Env, scene: &str, look: Look, frames: u64, out: &Path) -> Result<RunSummary> {
    let mut sw = env.switches.clone();
    sw.frame.width = Some(env.width);
    sw.frame.height = Some(env.width);
    (sw.metaball.surface, sw.metaball.mesh_cell) = (Some(look.0), look.1);
    sw.common.particles = look.2;
    sw.common.quiet = true;
    sw.view.render = Some(RenderKind::Metaballs);
    let opts = crate::run::RunOptions {
        scene: scene.into(),
        frames: Some(frames),
        out: out.to_path_buf(),
        save_every: frames.saturating_sub(1).max(1),
        switches: sw,
    };
    Ok(crate::run::run(&opts)?.summary)
}

/// The renderer's bytes: the buffers it holds (summary.json's `renderer_bytes`).
fn render_bytes(s: &RunSummary) -> u64 {
    s.stats.render().map_or(0, |r| r.renderer_bytes)
}

/// The sub-scopes of `render` with their medians: "splat 1.2, smooth 0.8, ...".
fn passes(s: &RunSummary) -> String {
    let p = s.pass_ms.0.iter();
    p.filter_map(|(k, v)| Some((k.strip_prefix("render/")?, v.median)))
        .map(|(k, v)| format!("{k} {v:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

pub fn surfaces(env: &mut Env) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let total = (SCENES.len() * SURFACES.len() + 1) as u64;
    let mut steps = Steps::new("surfaces", total, env.switches.common.quiet);
    let side = env.width;
    let mut md = format!(
        "# Surfaces: metaballs, screen-space fluid, marching cubes\n\n\
         Each scene played once per surface (`fluidform run --scene S --surface K --width \
         {side} --height {side}`, the scene's material; metaballs with the S-buffer, sorted for glass and tinted as by default), the same \
         simulation each time. GPU medians per frame of the `render` scope and its passes; \
         memory: the buffers the renderer holds (`renderer_bytes` of summary.json); the last frame of \
         each, left to right in the table's order.\n\n\
         | scene | surface | frames | render ms | x metaballs | passes (ms) | renderer MiB | triangles |\n\
         |---|---|---|---|---|---|---|---|\n"
    );
    let mut csv = String::from("scene,surface,frames,render_ms,speedup,renderer_bytes,triangles\n");
    let mut files = Vec::new();
    let mut rows: Vec<Vec<PathBuf>> = Vec::new();
    let mut speedup = None;
    for &(label, scene, full, quick) in SCENES {
        let frames = if env.quick { quick } else { full };
        let mut shots = Vec::new();
        let mut base = None;
        for kind in SURFACES {
            let name = format!("{scene}-{}", kind.as_str());
            steps.start(&name);
            let out = env.runs(Experiment::Surfaces).join(&name);
            let s = play(env, scene, (kind, None, None), frames, &out)?;
            steps.tick();
            let ms = s.pass_median(crate::render::SCOPE)?;
            let b = *base.get_or_insert(ms);
            let last = s.stats.render().and_then(|r| r.last_frame.as_ref());
            let tris = last.map_or(0, |f| f.triangles);
            let bytes = render_bytes(&s);
            md.push_str(&format!(
                "| {label} | {} | {frames} | {ms:.2} | {:.1} | {} | {:.1} | {} |\n",
                kind.as_str(),
                b / ms,
                passes(&s),
                bytes as f64 / (1 << 20) as f64,
                if kind == SurfaceKind::Mesh {
                    tris.to_string()
                } else {
                    "-".into()
                }
            ));
            csv.push_str(&format!(
                "{label},{},{frames},{ms:.4},{:.3},{bytes},{tris}\n",
                kind.as_str(),
                b / ms
            ));
            if kind == SurfaceKind::ScreenSpace && scene == "character" {
                speedup = Some(b / ms);
            }
            let last = std::fs::read_dir(&out)
                .map_err(|e| super::io(&out, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "png"))
                .filter(|p| {
                    p.file_name()
                        .is_some_and(|f| f.to_string_lossy().starts_with("frame_"))
                })
                .max();
            shots.extend(last);
        }
        rows.push(shots);
    }
    let png = env.out.join("surfaces.png");
    grid_of(&rows, &png)?;
    files.push(png);
    // The marching cubes at the spacing against one SPH step, 64K particles (4K quick).
    let n = if env.quick { 4096 } else { 65536 };
    steps.start("cubes at 64K");
    let out = env.runs(Experiment::Surfaces).join("cubes-64k");
    let frames = if env.quick { 3 } else { 10 };
    let look = (SurfaceKind::Mesh, Some(1.0), Some(n));
    let s = play(env, "dam-break", look, frames, &out)?;
    steps.tick();
    steps.finish();
    let cubes = s.pass_median(DENSITY_SCOPE)? + s.pass_median(CELLS_SCOPE)?;
    let steps_run = s.stats.sph().map_or(f64::NAN, |p| p.steps as f64);
    let per_frame = steps_run / s.frames as f64;
    let step = s.pass_median(crate::sph::SCOPE)? / per_frame;
    let labels: Vec<&str> = SCENES.iter().map(|s| s.0).collect();
    md.push_str(&format!(
        "\nThe last frame of each: metaballs, screen-space, mesh (left to right); {} (top to \
         bottom).\n\n![surfaces](surfaces.png)\n\n",
        labels.join(", ")
    ));
    md.push_str(&format!(
        "Marching cubes at the particle spacing (`--mesh-cell 1`), dam break with {n} \
         particles: density {:.2} ms + cells {:.2} ms = **{cubes:.2} ms** per frame against \
         **{step:.2} ms** per SPH step (the `sph` scope's median over {per_frame:.0} steps a \
         frame); drawing the soup (raster) {:.2} ms.\n",
        s.pass_median(DENSITY_SCOPE)?,
        s.pass_median(CELLS_SCOPE)?,
        s.pass_median(RASTER_SCOPE)?,
    ));
    csv.push_str(&format!(
        "dam break {n},cubes-vs-step,{frames},{cubes:.4},{:.3},,\n",
        step / cubes
    ));
    let found = vec![
        match speedup {
            Some(x) => Finding::new(
                SCREEN_FASTER,
                Verdict::of(x >= 5.0),
                format!("{x:.1}x at {side}x{side}"),
            ),
            None => Finding::new(SCREEN_FASTER, Verdict::NotMeasured, String::new()),
        },
        Finding::new(
            CUBES_CHEAP,
            Verdict::of(cubes < step),
            format!("{cubes:.2} ms against {step:.2} ms at {n} particles"),
        ),
    ];
    let p_csv = env.out.join("surfaces.csv");
    write(&p_csv, &csv)?;
    let p_md = super::finish_md(env, Experiment::Surfaces, md, &found)?;
    files.push(p_csv);
    files.push(p_md);
    Ok((files, found))
}

/// The PNGs in rows, left to right and top to bottom (each cell the largest one's size).
fn grid_of(rows: &[Vec<PathBuf>], out: &Path) -> Result<()> {
    let load = |p: &PathBuf| {
        image::open(p)
            .map(|i| i.to_rgba8())
            .map_err(|e| Error::Param(format!("{}: {e}", p.display())))
    };
    let imgs = (rows.iter())
        .map(|r| r.iter().map(load).collect::<Result<Vec<_>>>())
        .collect::<Result<Vec<_>>>()?;
    let all = || imgs.iter().flatten();
    let (w, h) = (
        all().map(|i| i.width()).max().unwrap_or(1),
        all().map(|i| i.height()).max().unwrap_or(1),
    );
    let cols = imgs.iter().map(|r| r.len()).max().unwrap_or(1) as u32;
    let mut img = image::RgbaImage::new(w * cols.max(1), h * imgs.len().max(1) as u32);
    for (y, row) in imgs.iter().enumerate() {
        for (x, i) in row.iter().enumerate() {
            image::imageops::replace(&mut img, i, x as i64 * w as i64, y as i64 * h as i64);
        }
    }
    img.save(out)
        .map_err(|e| Error::Param(format!("{}: {e}", out.display())))
}
