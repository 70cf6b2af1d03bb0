//! A PNG beside every sweep table (plotters): cost per element against N per variant on
//! log-log axes where a variant has several N, else the median per variant as bars (list
//! modes, materials). Axes carry units; the title names the device and the date.
use super::Row;
use crate::error::{Error, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

/// DejaVu Sans from Debian's fonts-dejavu-core (installed by scripts/setup.sh).
const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
/// The same font embedded at build time (build.rs; empty where the build had none): a
/// GPU machine gets only the binary.
const EMBEDDED: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/font.ttf"));

pub(crate) fn err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Image {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Register the font once; plotters draws text with it.
pub(crate) fn font() -> Result<()> {
    static DONE: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        let bytes: &'static [u8] = match EMBEDDED.is_empty() {
            false => EMBEDDED,
            true => {
                let b = std::fs::read(FONT).map_err(|e| {
                    format!("{FONT}: {e} (install fonts-dejavu-core: scripts/setup.sh)")
                })?;
                Box::leak(b.into_boxed_slice())
            }
        };
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| format!("{FONT}: not a usable TrueType font"))
    })
    .clone()
    .map_err(|m| Error::Image {
        path: FONT.into(),
        message: m,
    })
}

/// Today's date (UTC) as YYYY-MM-DD.
pub fn today() -> String {
    crate::bench::provenance::today()
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// The series' legend, boxed on a pale ground (plotters' place unless `at`).
fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    path: &Path,
    at: Option<SeriesLabelPosition>,
) -> Result<()> {
    let mut labels = chart.configure_series_labels();
    if let Some(at) = at {
        labels.position(at);
    }
    labels
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(path, e))
}

/// The rows of a sweep.csv (`variant,n,reps,median_ms,min_ms,max_ms,...`).
pub fn read_sweep(path: &Path) -> Result<Vec<Row>> {
    let bad = |m: String| Error::Param(format!("{}: {m}", path.display()));
    let mut r = csv::Reader::from_path(path).map_err(|e| bad(e.to_string()))?;
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| bad(e.to_string()))?;
        let num = |i: usize| -> Result<f64> {
            rec.get(i)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| bad(format!("column {i} of {rec:?} is not a number")))
        };
        rows.push(Row {
            variant: rec.get(0).unwrap_or("").to_string(),
            n: num(1)? as u64,
            reps: num(2)? as u64,
            main: crate::report::Stat {
                median: num(3)?,
                min: num(4)?,
                max: num(5)?,
            },
            passes: Vec::new(),
            extra: Vec::new(),
            interval: None,
            flagged: false,
        });
    }
    if rows.is_empty() {
        return Err(bad("no rows".into()));
    }
    Ok(rows)
}

/// Write the sweep's plot to `path`; `title` names the benchmark, `scope` its timed scope.
pub fn sweep(path: &Path, title: &str, scope: &str, device: &str, rows: &[Row]) -> Result<()> {
    sweep_dated(path, title, scope, device, &today(), rows)
}

/// As `sweep`, with the date of the measurement.
pub fn sweep_dated(
    path: &Path,
    title: &str,
    scope: &str,
    device: &str,
    date: &str,
    rows: &[Row],
) -> Result<()> {
    font()?;
    // Rows without a time (a run that went unstable) have no point.
    let kept: Vec<Row> = rows
        .iter()
        .filter(|r| r.main.median.is_finite())
        .cloned()
        .collect();
    let rows = &kept[..];
    let mut variants: Vec<&str> = Vec::new();
    for r in rows {
        if !variants.contains(&r.variant.as_str()) {
            variants.push(&r.variant);
        }
    }
    let several_n = variants
        .iter()
        .any(|v| rows.iter().filter(|r| r.variant == *v).count() > 1);
    let caption = format!("{title}: {device}, {date}");
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    match several_n {
        true => per_element_lines(&root, path, &caption, scope, &variants, rows)?,
        false => bars(&root, path, &caption, scope, rows)?,
    }
    root.present().map_err(|e| err(path, e))
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Cost per element against N on log axes, one line per variant.
fn per_element_lines(
    root: &Area,
    path: &Path,
    caption: &str,
    scope: &str,
    variants: &[&str],
    rows: &[Row],
) -> Result<()> {
    let per = |r: &Row| r.main.median * 1e6 / r.n.max(1) as f64;
    let (nmin, nmax) = rows.iter().fold((f64::MAX, 0.0f64), |(a, b), r| {
        (a.min(r.n as f64), b.max(r.n as f64))
    });
    let (cmin, cmax) = rows.iter().fold((f64::MAX, 0.0f64), |(a, b), r| {
        (a.min(per(r)), b.max(per(r)))
    });
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(
            (nmin / 1.3..nmax * 1.3).log_scale(),
            // Whole decades: a log axis labels only its decades' ticks.
            (10f64.powf((cmin / 1.5).log10().floor())..10f64.powf((cmax * 1.5).log10().ceil()))
                .log_scale(),
        )
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("N (elements)")
        .y_desc(format!("{scope} ns per element"))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| {
            if *y >= 10.0 {
                format!("{y:.0}")
            } else {
                format!("{y:.2}")
            }
        })
        .draw()
        .map_err(|e| err(path, e))?;
    for (i, v) in variants.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.variant == *v)
            .map(|r| (r.n as f64, per(r)))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(|e| err(path, e))?
            .label(*v)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c));
        chart
            .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, c.filled())))
            .map_err(|e| err(path, e))?;
    }
    legend(&mut chart, path, None)?;
    Ok(())
}

/// The label of the bar centred at `x` (bar i spans [i, i + 1]); none between bars.
fn bar_label(labels: &[String], x: f64) -> String {
    let i = (x - 0.5).round();
    match (x - 0.5 - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
        true => labels[i as usize].clone(),
        false => String::new(),
    }
}

/// One bar per row (a single N each): the median, a line from min to max.
fn bars(root: &Area, path: &Path, caption: &str, scope: &str, rows: &[Row]) -> Result<()> {
    let ymax = rows.iter().map(|r| r.main.max).fold(0.0f64, f64::max);
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(0.0..rows.len() as f64, 0.0..ymax * 1.15)
        .map_err(|e| err(path, e))?;
    let labels: Vec<String> = rows
        .iter()
        .map(|r| format!("{} (N {})", r.variant, r.n))
        .collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(rows.len() * 2 + 1)
        .x_label_formatter(&|x| bar_label(&labels, *x))
        .y_desc(format!("{scope} ms (median, bar: min..max)"))
        .draw()
        .map_err(|e| err(path, e))?;
    for (i, r) in rows.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        let x = i as f64;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x + 0.15, 0.0), (x + 0.85, r.main.median)],
                c.filled(),
            )))
            .map_err(|e| err(path, e))?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x + 0.5, r.main.min), (x + 0.5, r.main.max)],
                BLACK.stroke_width(2),
            )))
            .map_err(|e| err(path, e))?;
    }
    Ok(())
}

/// Coverage over scene time, one line per variant (`series`: name, (time, coverage)).
pub fn coverage(
    path: &Path,
    title: &str,
    device: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    let y = "coverage (control particles with rho >= 0.5 rho0)";
    over_time(path, title, y, device, series)
}

/// Fractions (0..1) against scene time, one line per series, with a grey line at 0.9.
pub fn over_time(
    path: &Path,
    title: &str,
    y_desc: &str,
    device: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    font()?;
    let caption = format!("{title}: {device}, {}", today());
    let tmax = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .fold(0.0f64, f64::max)
        .max(1e-3);
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    let axes = (0.0..tmax, 0.0..1.0);
    let mut chart = line_chart(&root, path, &caption, axes, ("scene time (s)", y_desc))?;
    draw_lines(&mut chart, path, series)?;
    let gray = RGBColor(150, 150, 150);
    chart
        .draw_series(LineSeries::new(vec![(0.0, 0.9), (tmax, 0.9)], gray))
        .map_err(|e| err(path, e))?;
    legend(&mut chart, path, Some(SeriesLabelPosition::LowerRight))?;
    root.present().map_err(|e| err(path, e))
}

type Lines<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A white 900 x 560 ground with linear axes over `x` and `y`, described by `desc`.
fn line_chart<'a, 'b>(
    root: &'a Area<'b>,
    path: &Path,
    caption: &str,
    (x, y): (std::ops::Range<f64>, std::ops::Range<f64>),
    (x_desc, y_desc): (&str, &str),
) -> Result<Lines<'a, 'b>> {
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x, y)
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()
        .map_err(|e| err(path, e))?;
    Ok(chart)
}

/// One labelled line per series, in the palette's order.
fn draw_lines(chart: &mut Lines, path: &Path, series: &[(String, Vec<(f64, f64)>)]) -> Result<()> {
    for (i, (name, pts)) in series.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(|e| err(path, e))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c));
    }
    Ok(())
}

/// The surge front Z against T per solver (lines) with Martin & Moyce's points (black).
pub fn front(
    path: &Path,
    device: &str,
    series: &[(String, Vec<(f64, f64)>)],
    paper: &[(f64, f64)],
) -> Result<()> {
    font()?;
    let caption = format!(
        "collapsing column against Martin & Moyce: {device}, {}",
        today()
    );
    let all = series.iter().flat_map(|s| s.1.iter()).chain(paper);
    let (tmax, zmax) = all.fold((1.0f64, 1.0f64), |m, p| (m.0.max(p.0), m.1.max(p.1)));
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    let axes = (0.0..tmax * 1.05, 1.0..zmax * 1.05);
    let desc = ("T = t sqrt(2 g / a)", "front Z = z / a");
    let mut chart = line_chart(&root, path, &caption, axes, desc)?;
    draw_lines(&mut chart, path, series)?;
    chart
        .draw_series(paper.iter().map(|p| Circle::new(*p, 4, BLACK.filled())))
        .map_err(|e| err(path, e))?
        .label("Martin & Moyce 1952")
        .legend(|(x, y)| Circle::new((x + 9, y), 4, BLACK.filled()));
    legend(&mut chart, path, Some(SeriesLabelPosition::LowerRight))?;
    root.present().map_err(|e| err(path, e))
}

/// Grouped bars on a log axis: one group per label, one bar per series (missing values
/// leave a gap). `subtitle` names the device and date.
pub fn grouped_bars(
    path: &Path,
    title: &str,
    subtitle: &str,
    labels: &[String],
    series: &[(String, Vec<Option<f64>>)],
    y_desc: &str,
) -> Result<()> {
    font()?;
    let values = series.iter().flat_map(|(_, v)| v.iter().flatten().copied());
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::MAX, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = match hi > 0.0 {
        true => (lo, hi),
        false => (1.0, 10.0),
    };
    let y0 = 10f64.powf((lo / 1.5).log10().floor());
    let y1 = 10f64.powf((hi * 1.5).log10().ceil());
    let root = BitMapBackend::new(path, (1000, 580)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{title} ({subtitle})"), ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(60)
        .y_label_area_size(72)
        .build_cartesian_2d(0.0..labels.len() as f64, (y0..y1).log_scale())
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(labels.len() * 2 + 1)
        .x_label_formatter(&|x| bar_label(labels, *x))
        .y_desc(y_desc)
        .y_label_formatter(&|y| match *y >= 10.0 {
            true => format!("{y:.0}"),
            false => format!("{y:.2}"),
        })
        .draw()
        .map_err(|e| err(path, e))?;
    let k = series.len().max(1) as f64;
    let w = 0.8 / k;
    for (s, (name, vals)) in series.iter().enumerate() {
        let c = PALETTE[s % PALETTE.len()];
        let bars = vals.iter().enumerate().filter_map(|(i, v)| {
            let v = (*v)?;
            let x = i as f64 + 0.1 + s as f64 * w;
            Some(Rectangle::new(
                [(x, y0), (x + w * 0.9, v.max(y0))],
                c.filled(),
            ))
        });
        chart
            .draw_series(bars)
            .map_err(|e| err(path, e))?
            .label(name.as_str())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.filled()));
    }
    legend(&mut chart, path, Some(SeriesLabelPosition::UpperRight))?;
    root.present().map_err(|e| err(path, e))
}

/// Frames side by side with a label above each and a title: an image sheet.
pub fn sheet(
    path: &Path,
    title: &str,
    labels: &[String],
    images: &[Vec<u8>],
    (w, h): (u32, u32),
    cols: usize,
) -> Result<()> {
    font()?;
    // Tiles at most 256 pixels wide keep sheets small.
    let scale = (w.div_ceil(256)).max(1);
    let (tw, th) = (w / scale, h / scale);
    let cols = cols.max(1);
    let rows = labels.len().div_ceil(cols);
    let (pad, head, label) = (8u32, 36u32, 22u32);
    let sw = cols as u32 * (tw + pad) + pad;
    let sh = head + rows as u32 * (th + label + pad) + pad;
    let mut buf = vec![255u8; (sw * sh * 3) as usize];
    for (i, img) in images.iter().enumerate() {
        if img.len() != (w * h * 4) as usize {
            continue;
        }
        let (cx, cy) = ((i % cols) as u32, (i / cols) as u32);
        let (x0, y0) = (
            pad + cx * (tw + pad),
            head + cy * (th + label + pad) + label,
        );
        for y in 0..th {
            for x in 0..tw {
                let s = (((y * scale) * w + x * scale) * 4) as usize;
                let d = (((y0 + y) * sw + x0 + x) * 3) as usize;
                buf[d..d + 3].copy_from_slice(&img[s..s + 3]);
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (sw, sh)).into_drawing_area();
        let style = ("sans-serif", 18).into_font().color(&BLACK);
        root.draw_text(title, &style, (pad as i32, 8))
            .map_err(|e| err(path, e))?;
        let small = ("sans-serif", 15).into_font().color(&BLACK);
        for (i, l) in labels.iter().enumerate() {
            let (cx, cy) = ((i % cols) as u32, (i / cols) as u32);
            let (x0, y0) = (pad + cx * (tw + pad), head + cy * (th + label + pad));
            root.draw_text(l, &small, (x0 as i32, y0 as i32 + 3))
                .map_err(|e| err(path, e))?;
        }
        root.present().map_err(|e| err(path, e))?;
    }
    image::save_buffer(path, &buf, sw, sh, image::ExtendedColorType::Rgb8).map_err(|e| err(path, e))
}

/// A point of `error_cost`: (series, label, x, y).
pub type LabelledPoint = (String, String, f64, f64);

/// Density error against cost, log-log: one colour per series (solver), each point
/// labelled (e.g. its N). `points`: (series, label, GPU s per simulated s, mean error %).
pub fn error_cost(path: &Path, caption: &str, points: &[LabelledPoint]) -> Result<()> {
    font()?;
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(path, e))?;
    let range = |f: &dyn Fn(&LabelledPoint) -> f64| {
        let (a, b) = points
            .iter()
            .map(f)
            .filter(|v| v.is_finite() && *v > 0.0)
            .fold((f64::MAX, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        if b <= 0.0 {
            (0.1, 10.0)
        } else {
            (
                10f64.powf((a / 1.5).log10().floor()),
                10f64.powf((b * 1.5).log10().ceil()),
            )
        }
    };
    let (x0, x1) = range(&|p| p.2);
    let (y0, y1) = range(&|p| p.3);
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| err(path, e))?;
    chart
        .configure_mesh()
        .x_desc("GPU seconds per simulated second (lower is cheaper)")
        .y_desc("mean density error %")
        .x_label_formatter(&|x| format!("{x}"))
        .y_label_formatter(&|y| format!("{y}"))
        .draw()
        .map_err(|e| err(path, e))?;
    let mut series: Vec<&str> = Vec::new();
    for p in points {
        if !series.contains(&p.0.as_str()) {
            series.push(&p.0);
        }
    }
    for (i, s) in series.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        let pts: Vec<_> = points.iter().filter(|p| p.0 == *s).collect();
        chart
            .draw_series(pts.iter().map(|p| Circle::new((p.2, p.3), 5, c.filled())))
            .map_err(|e| err(path, e))?
            .label(*s)
            .legend(move |(x, y)| Circle::new((x + 9, y), 5, c.filled()));
        chart
            .draw_series(pts.iter().map(|p| {
                Text::new(
                    p.1.clone(),
                    (p.2 * 1.08, p.3),
                    ("sans-serif", 13).into_font().color(&c),
                )
            }))
            .map_err(|e| err(path, e))?;
    }
    legend(&mut chart, path, None)?;
    root.present().map_err(|e| err(path, e))
}
