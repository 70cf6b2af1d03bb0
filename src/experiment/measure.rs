//! Measure one thesis table on the thesis scene and write its CSV, markdown, plot, image
//! sheet and findings.
use super::findings::{self, Finding, Verdict};
use super::shots::{time_shots, Shot};
use super::tables::{value, Col, TableDef, SBUFFER};
use super::{write, Env, Steps};
use crate::bench::interval::Estimate;
use crate::bench::Measurer;
use crate::error::Result;
use crate::gpu::{Context, Guard};
use crate::render::metaball::MetaballSettings;
use crate::report::Stat;
use serde_json::json;
use std::path::PathBuf;

/// One (row, column) of a table.
pub struct Cell {
    pub stat: Stat,
    /// The median's 95% interval under the protocol, and whether the row was flagged.
    pub est: Estimate,
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
    Ok(MetaballSettings {
        width,
        height,
        ..MetaballSettings::thesis()
    })
}

pub fn table(ctx: &Context, env: &mut Env, def: TableDef) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let m = run(ctx, env, &def)?;
    let found = verdicts(&def, &m);
    let files = write_table(env, &def, &m)?;
    Ok((files, found))
}

/// Every cell of the table, timed together under the protocol (shots.rs).
fn run(ctx: &Context, env: &mut Env, def: &TableDef) -> Result<Measured> {
    let seed = env.switches.common.seed;
    let base_centers = env.scene(ctx)?.centers.clone();
    let cam = env.scene(ctx)?.camera;
    let opts = env.bench_options(Measurer::Experiment(def.name.as_str()), def.name);
    let (width, height) = (env.width, env.height);
    let mut steps = Steps::new(
        &def.name.as_str(),
        def.rows.len() as u64 + 1,
        env.switches.common.quiet,
    );
    // Every row's centres first: the protocol interleaves every cell of the table.
    let mut labels = Vec::new();
    let mut particles = Vec::new();
    let mut bufs = Guard::new(ctx, Vec::new());
    for row in &def.rows {
        steps.start(&format!("{} centres", row.label));
        let centers = match row.change.particles {
            Some(f) => {
                let n = (base_centers.len() as f64 * f).round() as usize;
                env.scene(ctx)?.with_particles(n, seed)?
            }
            None => base_centers.clone(),
        };
        let n = centers.len();
        labels.push(match row.change.particles {
            Some(_) => format!("N={n}"),
            None => row.label.clone(),
        });
        particles.push(n);
        bufs.push(ctx.storage_buffer("thesis centers", (n * 16) as u64)?);
        ctx.upload(bufs.last_mut().expect("pushed"), 0, &centers)?;
        steps.tick();
    }
    let mut shots = Vec::new();
    for (r, row) in def.rows.iter().enumerate() {
        for col in &def.cols {
            let mut s = base(width, height)?;
            row.change.apply(&mut s);
            s.list = col.list;
            s.sorted = col.sorted;
            s.validate()?;
            let label = &labels[r];
            let detail = json!({ "table": def.name.as_str(), "row": label, "list": col.name,
                "settings": s, "particles": particles[r] });
            shots.push(Shot {
                variant: format!("{}-{}", slug(label), col.name),
                settings: s,
                centers: &bufs[r],
                centers_key: format!("thesis {} seed {seed}", particles[r]),
                n: particles[r] as u32,
                cam,
                detail,
            });
        }
    }
    steps.start("every cell, interleaved");
    let timed = time_shots(ctx, env, &opts, &shots)?;
    steps.tick();
    steps.finish();
    let mut out = Measured {
        labels,
        particles,
        cells: Vec::new(),
        images: Vec::new(),
    };
    for row in timed.chunks(def.cols.len()) {
        let mut image = Vec::new();
        let cells = row
            .iter()
            .zip(&def.cols)
            .map(|(t, col)| {
                if *col == SBUFFER {
                    image = t.pixels.clone();
                }
                Cell {
                    stat: t.row.main,
                    est: t.row.estimate().unwrap_or_default(),
                    reps: t.row.reps,
                    fps: 1000.0 / t.row.main.median,
                    list_bytes: t.sized.list_bytes,
                    fragments: t.sized.fragments,
                    longest: t.sized.longest,
                    budget_pixels: t.sized.budget_pixels.max(t.after.budget_pixels) as u64,
                }
            })
            .collect();
        out.cells.push(cells);
        out.images.push(image);
    }
    Ok(out)
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
    // Per row: S faster than A, A faster than none, each beyond the intervals.
    let per_row: Vec<Verdict> = m
        .cells
        .iter()
        .map(|c| {
            Verdict::all([
                Verdict::faster(&c[s].est, &c[a].est),
                Verdict::faster(&c[a].est, &c[none].est),
            ])
        })
        .collect();
    let bad: Vec<String> = m
        .cells
        .iter()
        .zip(&m.labels)
        .zip(&per_row)
        .filter(|(_, v)| **v != Verdict::Confirmed)
        .map(|((c, l), v)| {
            format!(
                "{l} ({}): S {}, A {}, none {}",
                v.word(),
                c[s].est.text(),
                c[a].est.text(),
                c[none].est.text()
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
        Verdict::all(per_row.iter().copied()),
        format!(
            "{} of {} rows hold beyond their intervals; mean speed-up over none: S-buffer \
             {:.1}x, A-buffer {:.1}x; S over A {:.2}x to {:.2}x{}",
            m.cells.len() - bad.len(),
            m.cells.len(),
            ratio(s),
            ratio(a),
            sa.iter().cloned().fold(f64::INFINITY, f64::min),
            sa.iter().cloned().fold(0.0, f64::max),
            match bad.is_empty() {
                true => String::new(),
                false => format!(" (not: {})", bad.join("; ")),
            }
        ),
    ));
    found.push(memory_finding(m, s, a));
    found.push(findings::sixfold_k2(def, m));
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
    let mut verdicts = Vec::new();
    for g in groups {
        for (k, col) in def.cols.iter().enumerate() {
            let cells: Vec<&Cell> = g.iter().map(|&r| &m.cells[r][k]).collect();
            let v = Verdict::all(
                cells
                    .windows(2)
                    .map(|w| Verdict::faster(&w[0].est, &w[1].est)),
            );
            verdicts.push(v);
            if v != Verdict::Confirmed {
                fails.push(format!(
                    "{} over {} ({}): {}",
                    col.name,
                    g.iter()
                        .map(|&r| m.labels[r].as_str())
                        .collect::<Vec<_>>()
                        .join(" < "),
                    v.word(),
                    cells
                        .iter()
                        .map(|c| c.est.text())
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
    }
    let checks = verdicts.len();
    Finding::new(
        claim,
        Verdict::all(verdicts),
        format!(
            "{} of {checks} series (per list) rise beyond their intervals{}",
            checks - fails.len(),
            match fails.is_empty() {
                true => String::new(),
                false => format!("; not: {}", fails.join("; ")),
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
    md.push_str(&setup_text(env, def, m)?);
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
         thesis_k1_fps,thesis_k2_fps,thesis_k2_speedup_vs_none,thesis_memory_mb,ci_lo_ms,ci_hi_ms,\
         flagged\n",
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
                "{},\"{}\",{},{},{},{},{},{:.4},{:.4},{:.4},{:.3},{:.3},{:.3},{},{:.1},{},{},{},{},{},{},{:.4},{:.4},{}\n",
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
                mem,
                c.est.interval.lo,
                c.est.interval.hi,
                c.est.flagged
            ));
        }
    }
    csv
}

/// The paragraph on the setup: scene, camera, timing.
fn setup_text(env: &Env, def: &TableDef, m: &Measured) -> Result<String> {
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
         time under the protocol below (the detail table gives each cell's frames). Speed-ups \
         are over the row's `none`, so devices compare. {}\n\n",
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
        crate::bench::protocol_text(
            &env.bench_options(Measurer::Experiment(def.name.as_str()), def.name)
        ),
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
    md.push_str(
        "\nTiming detail: median of the per-round medians, ms, [its 95% interval] (frames); \
         flagged: a round stayed off after its rerun (rounds.csv).\n\n| row |",
    );
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
                " {:.2} [{:.2}, {:.2}] ({}){} |",
                c.stat.median,
                c.est.interval.lo,
                c.est.interval.hi,
                c.reps,
                if c.est.flagged { " flagged" } else { "" }
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
