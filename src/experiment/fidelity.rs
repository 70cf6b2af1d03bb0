//! `fluidform experiment fidelity`: each liquid-character scene (the default walker,
//! CesiumMan from a scene file naming only him and a pool, the giraffe) with the thesis's control and with the
//! fidelity preset: the fidelity metrics side by side (means over the second half of each
//! run), the last saved frame of each (same scene time), and fill and IoU over time.
use super::findings::Finding;
use super::{write, Env, Experiment, Steps};
use crate::control::metrics::ControlRow;
use crate::control::ControlPreset;
use crate::error::{Error, Result};
use crate::render::RenderKind;
use std::path::{Path, PathBuf};

/// (label, scene, frames with --quick).
const SCENES: &[(&str, &str, u64)] = &[
    ("walker (default)", "character", 24),
    ("CesiumMan", "tests/scenes/cesium_man_pool.toml", 24),
    ("giraffe", "giraffe", 24),
];
const PRESETS: [ControlPreset; 2] = [ControlPreset::Thesis, ControlPreset::Fidelity];

/// One run's numbers.
struct Outcome {
    summary: crate::run::RunSummary,
    rows: Vec<ControlRow>,
    frame: Option<PathBuf>,
}

fn play(
    env: &Env,
    scene: &str,
    preset: ControlPreset,
    frames: Option<u64>,
    out: &Path,
) -> Result<Outcome> {
    let mut sw = env.switches.clone();
    sw.common.quiet = true;
    sw.control.control_preset = Some(preset);
    sw.view.render = Some(RenderKind::Metaballs);
    let opts = crate::run::RunOptions {
        scene: scene.into(),
        frames,
        out: out.to_path_buf(),
        save_every: 10,
        switches: sw,
    };
    let r = crate::run::run(&opts)?;
    let csv = out.join("control.csv");
    let mut rows = Vec::new();
    let mut rd = csv::Reader::from_path(&csv)
        .map_err(|e| Error::Param(format!("{}: {e}", csv.display())))?;
    for row in rd.deserialize() {
        rows.push(row.map_err(|e| Error::Param(format!("{}: {e}", csv.display())))?);
    }
    Ok(Outcome {
        summary: r.summary,
        rows,
        frame: r.pngs.last().cloned(),
    })
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |x| format!("{x:.digits$}"))
}

/// Every scene with each preset: the table, the CSV, the plots and the frames side by
/// side. Long because a scene's two runs share its frames and its unstable-run rows.
pub fn fidelity(env: &mut Env) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let mut steps = Steps::new(
        "fidelity",
        (SCENES.len() * PRESETS.len()) as u64,
        env.switches.common.quiet,
    );
    let mut md = String::from(
        "# Liquid-character fidelity: the thesis's control against the fidelity preset\n\n\
         Each scene played twice (`fluidform run --scene S --control-preset thesis|fidelity`, \
         metaballs at the scene's look). Metrics as the README defines them (\"Fidelity \
         metrics\"), mean over the second half of each run (min in brackets); control share: \
         the `sph/control` scopes over the `sph` scope (GPU medians per frame).\n\n\
         | scene | control | frames | fill | iou | spray | surface p95 | density in shape | speed excess m/s | time to 90% s | control share |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from("scene,preset,frames,fill_mean,fill_min,iou_mean,iou_min,spray_mean,surface_p95_mean,density_in_shape_mean,speed_excess_mean,time_to_90_s,control_share\n");
    let mut files = Vec::new();
    let mut pictures = Vec::new();
    let (mut fill_series, mut iou_series) = (Vec::new(), Vec::new());
    for &(label, scene, quick_frames) in SCENES {
        if scene.ends_with(".toml") && !Path::new(scene).exists() {
            md.push_str(&format!("| {label} | - | - | not run: {scene} is not here (run from the repository root with ../shared beside it) | | | | | | | |\n"));
            continue;
        }
        let frames = env.quick.then_some(quick_frames);
        let mut shots = Vec::new();
        for preset in PRESETS {
            let name = format!(
                "{}-{}",
                scene
                    .rsplit('/')
                    .next()
                    .unwrap_or(scene)
                    .trim_end_matches(".toml"),
                preset.as_str()
            );
            steps.start(&name);
            let played = play(
                env,
                scene,
                preset,
                frames,
                &env.runs(Experiment::Fidelity).join(&name),
            );
            steps.tick();
            // A run that goes unstable is a result: its row says so.
            let o = match played {
                Ok(o) => o,
                Err(e @ Error::Unstable(_)) => {
                    let what = e.to_string().replace(['|', ','], ";");
                    md.push_str(&format!(
                        "| {label} | {} | - | {what} | | | | | | | |\n",
                        preset.as_str()
                    ));
                    csv.push_str(&format!("{label},{},,{what},,,,,,,,,\n", preset.as_str()));
                    continue;
                }
                Err(e) => return Err(e),
            };
            let cells = row_cells(label, preset, &o)?;
            md.push_str(&format!("| {} |\n", cells.join(" | ")));
            // (The csv splits mean and min.)
            let mut c = cells.to_vec();
            c[3] = c[3].replace(" (", ",").replace(')', "");
            c[4] = c[4].replace(" (", ",").replace(')', "");
            csv.push_str(&format!("{}\n", c.join(",")));
            let series = |f: fn(&ControlRow) -> f64| {
                o.rows.iter().map(|r| (r.time, f(r))).collect::<Vec<_>>()
            };
            fill_series.push((format!("{label} {}", preset.as_str()), series(|r| r.fill)));
            iou_series.push((format!("{label} {}", preset.as_str()), series(|r| r.iou)));
            if let Some(f) = o.frame {
                shots.push((preset, f));
            }
        }
        // The two frames side by side (thesis left).
        if shots.len() == 2 {
            let slug: String = label
                .chars()
                .take_while(|c| c.is_alphanumeric())
                .collect::<String>()
                .to_lowercase();
            let png = env.out.join(format!("fidelity-{slug}.png"));
            side_by_side(&shots[0].1, &shots[1].1, &png)?;
            pictures.push((label, png.clone()));
            files.push(png);
        }
    }
    steps.finish();
    let plots = plots(env, &mut md, (&fill_series, &iou_series), &pictures)?;
    let p_csv = env.out.join("fidelity.csv");
    write(&p_csv, &csv)?;
    let p_md = super::finish_md(env, Experiment::Fidelity, md, &[])?;
    files.push(p_csv);
    files.push(p_md);
    files.extend(plots);
    Ok((files, Vec::new()))
}

type Series = Vec<(String, Vec<(f64, f64)>)>;

/// Fill and IoU over time for every run, and the frames side by side, into `md`.
fn plots(
    env: &Env,
    md: &mut String,
    (fill_series, iou_series): (&Series, &Series),
    pictures: &[(&str, PathBuf)],
) -> Result<[PathBuf; 2]> {
    let device = env.meta.device.clone();
    let fill_png = env.out.join("fidelity.png");
    let y = "fill (interior voxels with rho >= 0.5 rho0)";
    crate::bench::plot::over_time(&fill_png, "fill over time", y, &device, fill_series)?;
    let iou_png = env.out.join("fidelity-iou.png");
    let y = "IoU near the target";
    crate::bench::plot::over_time(&iou_png, "IoU over time", y, &device, iou_series)?;
    md.push_str("\n![fill over time](fidelity.png)\n\n![IoU over time](fidelity-iou.png)\n\n");
    for (label, png) in pictures {
        let f = png.file_name().and_then(|f| f.to_str()).unwrap_or_default();
        md.push_str(&format!(
            "{label}, the last saved frame: thesis (left), fidelity (right)\n\n![{label}]({f})\n\n"
        ));
    }
    Ok([fill_png, iou_png])
}

/// A run's row: metrics (mean, min in brackets), time to 90% and the control's share.
fn row_cells(label: &str, preset: ControlPreset, o: &Outcome) -> Result<[String; 11]> {
    let sph = o.summary.stats.sph();
    let t = sph.and_then(|s| s.control.as_ref()?.targets.first());
    let w = t.and_then(|t| t.fidelity.as_ref());
    // A metric's (mean, min) as cells: `-` where the run has none.
    type Pick = fn(&crate::control::metrics::Window) -> Option<crate::control::metrics::MeanMin>;
    let m = |f: Pick| {
        let v = w.and_then(f);
        (cell(v.map(|v| v.mean), 3), cell(v.map(|v| v.min), 3))
    };
    let mean = |f: Pick, digits| cell(w.and_then(f).map(|v| v.mean), digits);
    let median = |k| o.summary.pass_median(k);
    let share = match (
        median(crate::control::force::SCOPE)?,
        median(crate::sph::SCOPE)?,
    ) {
        (c, s) if s > 0.0 => format!("{:.2}", c / s),
        _ => "-".into(),
    };
    let t90 = cell(t.and_then(|t| t.time_to_90), 2);
    let n = o.rows.len();
    let cells = [
        label.to_string(),
        preset.as_str().to_string(),
        n.to_string(),
        format!("{} ({})", m(|w| w.fill).0, m(|w| w.fill).1),
        format!("{} ({})", m(|w| w.iou).0, m(|w| w.iou).1),
        mean(|w| w.spray, 4),
        mean(|w| w.surface_p95, 2),
        m(|w| w.density_in_shape).0,
        mean(|w| w.speed_excess, 2),
        t90,
        share,
    ];
    Ok(cells)
}

/// `a` and `b` side by side in one PNG (a on the left), each at its own size.
fn side_by_side(a: &Path, b: &Path, out: &Path) -> Result<()> {
    let load = |p: &Path| {
        image::open(p)
            .map(|i| i.to_rgba8())
            .map_err(|e| Error::Param(format!("{}: {e}", p.display())))
    };
    let (a, b) = (load(a)?, load(b)?);
    let mut img = image::RgbaImage::new(a.width() + b.width(), a.height().max(b.height()));
    image::imageops::replace(&mut img, &a, 0, 0);
    image::imageops::replace(&mut img, &b, a.width() as i64, 0);
    img.save(out)
        .map_err(|e| Error::Param(format!("{}: {e}", out.display())))
}
