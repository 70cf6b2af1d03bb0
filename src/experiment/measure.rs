//! Measure one thesis table on the thesis scene and write its CSV, markdown, plot, image
//! sheet and findings.
use super::findings::{self, Finding, Verdict};
use super::tables::{value, Col, TableDef, SBUFFER};
use super::{write, Env, Steps};
use crate::bench::{measure as bench_measure, Measurer};
use crate::config::ListKind;
use crate::error::Result;
use crate::gpu::Context;
use crate::render::metaball::MetaballSettings;
use crate::report::Stat;
use serde_json::json;
use std::path::PathBuf;

/// One (row, column) of a table.
pub struct Cell {
    pub stat: Stat,
    pub reps: u64,
    pub fps: f64,
    pub list_bytes: u64,
    pub fragments: u64,
    pub longest: u32,
    pub budget_pixels: u64,
}

pub struct Measured {
    pub labels: Vec<String>,
    pub particles: Vec<usize>,
    /// `[row][col]`
    pub cells: Vec<Vec<Cell>>,
    /// The thesis's S-buffer frame of each row (RGBA).
    pub images: Vec<Vec<u8>>,
}

fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// The thesis defaults (Wyvill, T 0.9, R 0.04, I 2, Phong, depth 1) at the table's size.
pub fn base(width: u32, height: u32) -> Result<MetaballSettings> {
    let mut s = crate::settings::metaball_settings(&crate::config::Switches::default())?;
    s.width = width;
    s.height = height;
    Ok(s)
}

pub fn table(ctx: &Context, env: &mut Env, def: TableDef) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let m = run(ctx, env, &def)?;
    let found = verdicts(&def, &m);
    let files = write_table(env, &def, &m)?;
    Ok((files, found))
}

/// Every cell of the table, row by row. Long because a row's centre buffer must be freed
/// on every path, so its lists' measurements sit inside one closure.
fn run(ctx: &Context, env: &mut Env, def: &TableDef) -> Result<Measured> {
    let seed = env.switches.common.seed;
    let base_centers = env.scene(ctx)?.centers.clone();
    let cam = env.scene(ctx)?.camera;
    let opts = env.bench_options(Measurer::Experiment(def.name), def.name);
    let (width, height) = (env.width, env.height);
    let mut steps = Steps::new(
        &def.name.as_str(),
        (def.rows.len() * def.cols.len()) as u64,
        env.switches.common.quiet,
    );
    let mut out = Measured {
        labels: Vec::new(),
        particles: Vec::new(),
        cells: Vec::new(),
        images: Vec::new(),
    };
    for row in &def.rows {
        let centers = match row.change.particles {
            Some(f) => {
                let n = (base_centers.len() as f64 * f).round() as usize;
                env.scene(ctx)?.with_particles(n, seed)?
            }
            None => base_centers.clone(),
        };
        let n = centers.len();
        let label = match row.change.particles {
            Some(_) => format!("N={n}"),
            None => row.label.clone(),
        };
        let mut buf = ctx.storage_buffer("thesis centers", (n * 16) as u64)?;
        let mut cells = Vec::new();
        let mut image = Vec::new();
        let result = (|| -> Result<()> {
            ctx.upload(&mut buf, 0, &centers)?;
            for col in &def.cols {
                steps.start(&format!("{label} {}", col.name));
                let mut s = base(width, height)?;
                row.change.apply(&mut s);
                s.list = col.list;
                s.sorted = col.sorted;
                s.validate()?;
                let (r, b) = env.renderer(ctx, &s, n as u64)?;
                // Size the lists before timing (none has none: its frames are the slowest,
                // so it is not drawn once more; its statistics come from the timed frames).
                let sized = match col.list {
                    ListKind::None => None,
                    _ => Some(r.render_sync(ctx, b, &buf, n as u32, &cam, 0)?),
                };
                let redos = sized.map_or(0, |s| s.1);
                if *col == SBUFFER {
                    image = b.pixels(0).to_vec();
                }
                let detail = json!({ "table": def.name.as_str(), "row": label, "list": col.name,
                    "settings": s, "particles": n, "redos": redos });
                let variant = format!("{}-{}", slug(&label), col.name);
                let frame = Frame {
                    r,
                    b,
                    centers: &buf,
                    n: n as u32,
                    cam: &cam,
                };
                let row = time_frame(ctx, &opts, &variant, detail, &frame)?;
                let after = r.frame_stats(b, 0);
                let st = sized.map_or(after, |s| s.0);
                cells.push(Cell {
                    stat: row.main,
                    reps: row.reps,
                    fps: 1000.0 / row.main.median,
                    list_bytes: st.list_bytes,
                    fragments: st.fragments,
                    longest: st.longest,
                    budget_pixels: st.budget_pixels.max(after.budget_pixels) as u64,
                });
                steps.tick();
            }
            Ok(())
        })();
        ctx.destroy_buffer(&mut buf);
        result?;
        out.labels.push(label);
        out.particles.push(n);
        out.cells.push(cells);
        out.images.push(image);
    }
    steps.finish();
    Ok(out)
}

/// A renderer's frame of `n` metaballs at `centers` seen by `cam`.
pub struct Frame<'a> {
    pub r: &'a crate::render::metaball::FluidRenderer,
    pub b: &'a crate::render::metaball::MetaballBuffers,
    pub centers: &'a crate::gpu::Buffer,
    pub n: u32,
    pub cam: &'a crate::render::Camera,
}

/// The bench's timed repetitions of one frame, the `render` scope its headline.
pub fn time_frame(
    ctx: &Context,
    opts: &crate::bench::BenchOptions,
    variant: &str,
    detail: serde_json::Value,
    f: &Frame,
) -> Result<crate::bench::Row> {
    bench_measure(
        ctx,
        opts,
        variant,
        f.n as u64,
        crate::render::SCOPE,
        detail,
        |prof, cmd| {
            prof.begin(ctx, cmd, crate::render::SCOPE.name());
            f.r.record(ctx, cmd, prof, f.b, f.centers, f.n, f.cam, 0)?;
            prof.end(ctx, cmd);
            Ok(())
        },
    )
}

fn col_index(def: &TableDef, name: &str) -> Option<usize> {
    def.cols.iter().position(|c| c.name == name)
}

/// The verdicts this table can give: list order and memory in every row, and the rises
/// along its axes (for every list).
fn verdicts(def: &TableDef, m: &Measured) -> Vec<Finding> {
    let (none, a, s) = (
        col_index(def, "none").expect("none"),
        col_index(def, "abuffer").expect("abuffer"),
        col_index(def, "sbuffer").expect("sbuffer"),
    );
    let mut found = Vec::new();
    let bad: Vec<String> = m
        .cells
        .iter()
        .zip(&m.labels)
        .filter(|(c, _)| !(c[s].fps > c[a].fps && c[a].fps > c[none].fps))
        .map(|(c, l)| {
            format!(
                "{l}: S {:.2}, A {:.2}, none {:.2} fps",
                c[s].fps, c[a].fps, c[none].fps
            )
        })
        .collect();
    let ratio = |k: usize| {
        let v: Vec<f64> = m.cells.iter().map(|c| c[k].fps / c[none].fps).collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    let sa: Vec<f64> = m.cells.iter().map(|c| c[s].fps / c[a].fps).collect();
    found.push(Finding::new(
        findings::ORDER,
        Verdict::of(bad.is_empty()),
        format!(
            "{} of {} rows hold; mean speed-up over none: S-buffer {:.1}x, A-buffer {:.1}x; \
             S over A {:.2}x to {:.2}x{}",
            m.cells.len() - bad.len(),
            m.cells.len(),
            ratio(s),
            ratio(a),
            sa.iter().cloned().fold(f64::INFINITY, f64::min),
            sa.iter().cloned().fold(0.0, f64::max),
            match bad.is_empty() {
                true => String::new(),
                false => format!(" (fails: {})", bad.join("; ")),
            }
        ),
    ));
    found.push(memory_finding(m, s, a));
    for (claim, groups) in &def.rises {
        found.push(rise_finding(def, m, claim, groups));
    }
    found
}

/// The S-buffer's lists smaller than the A-buffer's in every row.
fn memory_finding(m: &Measured, s: usize, a: usize) -> Finding {
    let mem_bad: Vec<&String> = m
        .cells
        .iter()
        .zip(&m.labels)
        .filter(|(c, _)| c[s].list_bytes >= c[a].list_bytes)
        .map(|(_, l)| l)
        .collect();
    let mr: Vec<f64> = m
        .cells
        .iter()
        .map(|c| c[s].list_bytes as f64 / c[a].list_bytes.max(1) as f64)
        .collect();
    Finding::new(
        findings::MEMORY,
        Verdict::of(mem_bad.is_empty()),
        format!(
            "S / A memory {:.2} to {:.2} over {} rows{}",
            mr.iter().cloned().fold(f64::INFINITY, f64::min),
            mr.iter().cloned().fold(0.0, f64::max),
            mr.len(),
            match mem_bad.is_empty() {
                true => String::new(),
                false => format!(
                    " (not below in: {})",
                    mem_bad
                        .iter()
                        .map(|s| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }
        ),
    )
}

/// A claim that times rise along groups of rows, checked for every list.
fn rise_finding(
    def: &TableDef,
    m: &Measured,
    claim: &'static str,
    groups: &[Vec<usize>],
) -> Finding {
    let mut fails = Vec::new();
    let mut checks = 0;
    for g in groups {
        for (k, col) in def.cols.iter().enumerate() {
            let ms: Vec<f64> = g.iter().map(|&r| m.cells[r][k].stat.median).collect();
            checks += 1;
            if !ms.windows(2).all(|w| w[1] > w[0]) {
                fails.push(format!(
                    "{} over {}: {} ms",
                    col.name,
                    g.iter()
                        .map(|&r| m.labels[r].as_str())
                        .collect::<Vec<_>>()
                        .join(" < "),
                    ms.iter()
                        .map(|v| format!("{v:.2}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
    }
    Finding::new(
        claim,
        Verdict::of(fails.is_empty()),
        format!(
            "{} of {checks} series (per list) rise{}",
            checks - fails.len(),
            match fails.is_empty() {
                true => String::new(),
                false => format!("; not in: {}", fails.join("; ")),
            }
        ),
    )
}

fn thesis_ratio(def: &TableDef, r: usize, k: usize) -> Option<f64> {
    let none = col_index(def, "none")?;
    let row = &def.rows[r];
    Some(value(row.thesis.get(k)?.k2)? / value(row.thesis.get(none)?.k2)?)
}

fn write_table(env: &Env, def: &TableDef, m: &Measured) -> Result<Vec<PathBuf>> {
    let csv = table_csv(env, def, m);
    let mut md = format!("# {}\n\n", def.title);
    md.push_str(&setup_text(env, m)?);
    for n in &def.notes {
        md.push_str(&format!("- {n}\n"));
    }
    md.push_str(&table_md(def, m));
    md.push_str(&detail_md(def, m));
    let png = speedup_plot(env, def, m)?;
    md.push_str(&format!(
        "\n![speed-up over none per row]({}.png)\n",
        def.name
    ));
    let mut files = vec![png];
    if def.sheet_cols > 0 {
        let sheet = env.out.join(format!("{}-frames.png", def.name));
        crate::bench::plot::sheet(
            &sheet,
            &format!("{}: S-buffer frame per row", def.name),
            &m.labels,
            &m.images,
            (env.width, env.height),
            def.sheet_cols,
        )?;
        md.push_str(&format!("\n![the rows' frames]({}-frames.png)\n", def.name));
        files.push(sheet);
    }
    let p = env.out.join(format!("{}.csv", def.name));
    write(&p, &csv)?;
    files.push(p);
    files.push(super::finish_md(env, def.name, md, &verdicts(def, m))?);
    Ok(files)
}

/// One CSV row per row and list: timings, list statistics and the thesis's numbers.
fn table_csv(env: &Env, def: &TableDef, m: &Measured) -> String {
    let none = col_index(def, "none").expect("none");
    let mut csv = String::from(
        "table,row,list,particles,width,height,reps,median_ms,min_ms,max_ms,fps,speedup_vs_none,\
         list_mb,fragments,fragments_per_metaball,longest_list,pixels_past_loop_budget,\
         thesis_k1_fps,thesis_k2_fps,thesis_k2_speedup_vs_none,thesis_memory_mb\n",
    );
    for (r, cells) in m.cells.iter().enumerate() {
        for (k, c) in cells.iter().enumerate() {
            let col: &Col = &def.cols[k];
            let th = def.rows[r].thesis.get(k).cloned().unwrap_or_default();
            let mem = match col.name {
                "abuffer" => def.rows[r].memory.0,
                "sbuffer" => def.rows[r].memory.1,
                _ => "",
            };
            csv.push_str(&format!(
                "{},\"{}\",{},{},{},{},{},{:.4},{:.4},{:.4},{:.3},{:.3},{:.3},{},{:.1},{},{},{},{},{},{}\n",
                def.name,
                m.labels[r],
                col.name,
                m.particles[r],
                env.width,
                env.height,
                c.reps,
                c.stat.median,
                c.stat.min,
                c.stat.max,
                c.fps,
                c.fps / cells[none].fps,
                c.list_bytes as f64 / 1e6,
                c.fragments,
                c.fragments as f64 / m.particles[r] as f64,
                c.longest,
                c.budget_pixels,
                th.k1,
                th.k2,
                thesis_ratio(def, r, k).map(|v| format!("{v:.3}")).unwrap_or_default(),
                mem
            ));
        }
    }
    csv
}

/// The paragraph on the setup: scene, camera, timing.
fn setup_text(env: &Env, m: &Measured) -> Result<String> {
    let scene = env.scene_ref()?;
    let mut md = String::new();
    md.push_str(&format!(
        "Setup (the thesis's, section 5): {} fluid particles at rest spacing {:.4} m filling \
         the built-in walker ({:.2} m tall, posed at t = {} s of its walk, lattice points \
         jittered by 15% of the spacing, seed {}), rendered at {}x{} with the thesis's \
         defaults (Wyvill, T = 0.9, R = 0.04 m, I = 2, Phong, depth 1) unless the row says \
         otherwise. The thesis gives no camera; its memory column implies about 1.0M list \
         fragments at 2048 particles (about {} per metaball at 512x512), so the camera is \
         moved until an S-buffer frame holds {} fragments ({} measured, {:.0} per metaball). \
         A frame is the renderer alone (bounds, lists, march) on a frozen scene: the \
         thesis's frame rates include its simulation step. Frame rates are 1000 / median GPU \
         time over {} timed repetitions after {} warm-up (fewer where a configuration \
         would exceed {} s: the detail table gives each). Speed-ups are over the row's \
         `none`, so devices compare.\n\n",
        m.particles.first().copied().unwrap_or(0),
        scene.spacing,
        scene.body.height,
        super::thesis::POSE_T,
        env.switches.common.seed,
        env.width,
        env.height,
        super::thesis::FRAGMENTS_PER_METABALL,
        scene.target_fragments,
        scene.fragments,
        scene.fragments as f64 / scene.centers.len() as f64,
        env.frames,
        env.warmup,
        env.budget_s,
    ));
    Ok(md)
}

/// The main table: frame rates against the thesis's, list memory, fragments.
fn table_md(def: &TableDef, m: &Measured) -> String {
    let none = col_index(def, "none").expect("none");
    let mut md = String::new();
    md.push_str("\n| row |");
    for c in &def.cols {
        md.push_str(&format!(
            " {} fps (x none) | thesis K1 / K2 (x none) |",
            c.name
        ));
    }
    md.push_str(" list MB A / S | thesis MB A / S | fragments |\n|---|");
    md.push_str(&"---|---|".repeat(def.cols.len()));
    md.push_str("---|---|---|\n");
    let a = col_index(def, "abuffer").expect("abuffer");
    let s = col_index(def, "sbuffer").expect("sbuffer");
    for (r, cells) in m.cells.iter().enumerate() {
        md.push_str(&format!("| {} |", m.labels[r]));
        for (k, c) in cells.iter().enumerate() {
            let th = def.rows[r].thesis.get(k).cloned().unwrap_or_default();
            let thesis = match (th.k1, th.k2) {
                ("", "") => "-".to_string(),
                ("", k2) => format!("- / {k2}"),
                (k1, k2) => format!("{k1} / {k2}"),
            };
            let tr = thesis_ratio(def, r, k)
                .filter(|_| k != none)
                .map(|v| format!(" ({v:.1}x)"))
                .unwrap_or_default();
            let ours = match k == none {
                true => format!("{:.2}", c.fps),
                false => format!("{:.2} ({:.1}x)", c.fps, c.fps / cells[none].fps),
            };
            md.push_str(&format!(" {ours} | {thesis}{tr} |"));
        }
        let (ma, ms) = def.rows[r].memory;
        md.push_str(&format!(
            " {:.1} / {:.1} | {} | {} |\n",
            cells[a].list_bytes as f64 / 1e6,
            cells[s].list_bytes as f64 / 1e6,
            match (ma, ms) {
                ("", "") => "-".to_string(),
                (x, y) => format!("{x} / {y}"),
            },
            cells[s].fragments
        ));
    }
    md
}

/// Timing detail per cell and the loop-budget warning.
fn detail_md(def: &TableDef, m: &Measured) -> String {
    let mut md = String::new();
    md.push_str("\nTiming detail: median ms [min, max] over the repetitions (reps).\n\n| row |");
    for c in &def.cols {
        md.push_str(&format!(" {} |", c.name));
    }
    md.push_str("\n|---|");
    md.push_str(&"---|".repeat(def.cols.len()));
    md.push('\n');
    for (r, cells) in m.cells.iter().enumerate() {
        md.push_str(&format!("| {} |", m.labels[r]));
        for c in cells {
            md.push_str(&format!(
                " {:.2} [{:.2}, {:.2}] ({}) |",
                c.stat.median, c.stat.min, c.stat.max, c.reps
            ));
        }
        md.push('\n');
    }
    let cut: u64 = m.cells.iter().flatten().map(|c| c.budget_pixels).sum();
    if cut > 0 {
        md.push_str(&format!(
            "\n**Warning:** {cut} pixels' rays were cut short by llvmpipe's loop budget in \
             some configurations (column pixels_past_loop_budget of the CSV): those rows \
             understate the cost.\n"
        ));
    }
    md
}

/// The speed-up bars over `none`, ours beside the thesis's.
fn speedup_plot(env: &Env, def: &TableDef, m: &Measured) -> Result<PathBuf> {
    let none = col_index(def, "none").expect("none");
    let png = env.out.join(format!("{}.png", def.name));
    let mut series: Vec<(String, Vec<Option<f64>>)> = Vec::new();
    for (k, c) in def.cols.iter().enumerate().filter(|(k, _)| *k != none) {
        series.push((
            format!("ours {}", c.name),
            m.cells
                .iter()
                .map(|cells| Some(cells[k].fps / cells[none].fps))
                .collect(),
        ));
        let th: Vec<Option<f64>> = (0..m.cells.len())
            .map(|r| thesis_ratio(def, r, k))
            .collect();
        if th.iter().any(|v| v.is_some()) {
            series.push((format!("thesis K2 {}", c.name), th));
        }
    }
    crate::bench::plot::grouped_bars(
        &png,
        &format!("{}: speed-up over none", def.title),
        &format!("{}, {}", env.meta.device, env.meta.date),
        &m.labels,
        &series,
        "frame rate / none's",
    )?;
    Ok(png)
}
