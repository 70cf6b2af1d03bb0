//! `fluidform experiment lists`: every metaball list mode, build and march on the thesis
//! frame (table 2's Phong and table 6's glass at recursion depth 3), with per-pass GPU
//! times, list memory and each frame's floor on this device; then the modes that apply on
//! the liquid character (the default demo). Findings: the compute-built S-buffer against
//! the A-buffer and the raster-built S-buffer, tiles against every per-pixel list, the
//! Lipschitz march's steps, the speed targets of the best mode, and the glass rays marched
//! by several lanes against one invocation a ray (issue 67).
use super::findings::{Finding, Verdict};
use super::measure::base;
use super::shots::{time_shots, Shot};
use super::{write, Env, Experiment, Steps};
use crate::bench::floor::Floor;
use crate::bench::interval::Estimate;
use crate::bench::Measurer;
use crate::error::{Error, Result};
use crate::gpu::Guard;
use crate::render::metaball::MetaballSettings;
use crate::render::{BuildKind, ListKind, MarchKind, Material, RenderKind};
use serde_json::json;
use std::path::PathBuf;

pub const COMPUTE_BEATS_ABUFFER: &str =
    "compute-built S-buffer faster than the A-buffer (thesis frame, Phong)";
pub const COMPUTE_AS_FAST: &str =
    "compute-built S-buffer at least as fast as the raster-built one, in either order";
pub const TILES_BEAT_LISTS: &str =
    "tiles faster than every per-pixel list (thesis frame, Phong and glass depth 3)";
pub const LIPSCHITZ_FEWER: &str = "lipschitz march takes fewer steps than the fixed one";
pub const BEST_PHONG: &str = "best list mode at least 2x the S-buffer (thesis frame, Phong)";
pub const BEST_GLASS: &str =
    "best list mode at least 2x the sorted S-buffer (thesis frame, glass depth 3)";
pub const DEMO_FASTER: &str =
    "the default demo's render pass at least 2x faster with the best list mode";
/// Issue 67: the sorted S-buffer's glass at depth 3 with the widest `--ray-lanes` the
/// device's subgroup holds (32 on NVIDIA, 8 on lavapipe) against one invocation a ray.
pub const PARALLEL_MARCH: &str =
    "the parallel march at least 4x the serial one on glass at depth 3";
/// The glass row whose rays are marched by several lanes: the thesis's sorted S-buffer.
const LANED: Mode = Mode(S, true, R, 16, FIXED);

/// A list mode: (list, sorted, build, tile, march).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Mode(ListKind, bool, BuildKind, u32, MarchKind);

const FIXED: MarchKind = MarchKind::Fixed;
const LIP: MarchKind = MarchKind::Lipschitz;
const R: BuildKind = BuildKind::Raster;
const C: BuildKind = BuildKind::Compute;
const S: ListKind = ListKind::Sbuffer;
const T: ListKind = ListKind::Tiles;

const MODES: &[Mode] = &[
    Mode(ListKind::Abuffer, false, R, 16, FIXED),
    Mode(S, false, R, 16, FIXED),
    Mode(S, true, R, 16, FIXED),
    Mode(S, false, C, 16, FIXED),
    Mode(S, true, C, 16, FIXED),
    Mode(T, false, C, 8, FIXED),
    Mode(T, false, C, 16, FIXED),
    Mode(T, false, C, 32, FIXED),
    Mode(S, false, R, 16, LIP),
    Mode(S, true, C, 16, LIP),
    Mode(T, false, C, 8, LIP),
    Mode(T, false, C, 16, LIP),
];

/// The modes played on the liquid character (its tinted look sorts S-buffers by default).
const CHARACTER: &[Mode] = &[
    Mode(S, true, R, 16, FIXED),
    Mode(S, true, C, 16, FIXED),
    Mode(T, false, C, 8, FIXED),
    Mode(T, false, C, 16, FIXED),
    Mode(T, false, C, 16, LIP),
];

impl Mode {
    fn apply(&self, s: &mut MetaballSettings) {
        (s.list, s.sorted, s.build, s.tile, s.march) = (self.0, self.1, self.2, self.3, self.4);
    }

    fn name(&self) -> String {
        let mut s = base(8, 8).expect("the thesis defaults");
        self.apply(&mut s);
        match self.4 {
            LIP => format!("{} lipschitz", s.list_name()),
            _ => s.list_name(),
        }
    }

    fn per_pixel(&self) -> bool {
        self.0 != T
    }
}

/// One measured configuration.
#[derive(Clone)]
struct Cell {
    mode: Mode,
    ms: f64,
    /// The median's 95% interval under the protocol, and whether the row was flagged.
    est: Estimate,
    passes: String,
    list_mb: f64,
    steps: f64,
    evals: f64,
    floor: f64,
    /// Lanes a ray (`--ray-lanes`) and the longest serial chain (`serial_max`).
    lanes: u32,
    serial: u64,
}

/// Glass at depth 3 costs ten Phong frames on lavapipe: the sorted lists and tiles up to
/// 16 pixels only (the unsorted ones and the A-buffer sum every metaball of a pixel at
/// each sample).
fn glass_mode(m: &Mode) -> bool {
    (m.0 == S && m.1) || (m.0 == T && m.3 <= 16)
}

fn every_mode(_: &Mode) -> bool {
    true
}

/// (label, material, depth, modes): table 2's Phong, table 6's glass at recursion depth 3.
type Look = (&'static str, Material, u32, fn(&Mode) -> bool);
const LOOKS: [Look; 2] = [
    ("Phong (table 2)", Material::Phong, 1, every_mode),
    ("glass, depth 3 (table 6)", Material::Glass, 3, glass_mode),
];

/// Every look's cells, then the glass cells of [`LANED`] marched by several lanes.
fn thesis_frame(
    ctx: &crate::gpu::Context,
    env: &mut Env,
    steps: &mut Steps,
) -> Result<(Vec<Vec<Cell>>, Vec<Cell>)> {
    let centers = env.scene(ctx)?.centers.clone();
    let cam = env.scene(ctx)?.camera;
    let n = centers.len();
    let opts = env.bench_options(
        Measurer::Experiment(Experiment::Lists.as_str()),
        Experiment::Lists,
    );
    let floor = Floor::measure(ctx, &opts)?;
    let mut buf = Guard::new(ctx, ctx.storage_buffer("thesis centers", (n * 16) as u64)?);
    ctx.upload(&mut buf, 0, &centers)?;
    // Every look's modes, timed together (the protocol interleaves them).
    let mut shots = Vec::new();
    let mut which = Vec::new();
    let laned = crate::render::metaball::settings::ray_lanes_on(&ctx.info)
        .into_iter()
        .filter(|&lanes| lanes > 1)
        .map(|lanes| (1, LOOKS[1].0, LANED, lanes));
    let every = LOOKS
        .into_iter()
        .enumerate()
        .flat_map(|(k, (label, _, _, modes))| {
            MODES
                .iter()
                .filter(move |m| modes(m))
                .map(move |m| (k, label, *m, 1))
        });
    for (k, label, mode, lanes) in every.chain(laned) {
        let (_, material, depth, _) = LOOKS[k];
        let mut s = base(env.width, env.height)?;
        (s.material, s.depth, s.ray_lanes) = (material, depth, lanes);
        mode.apply(&mut s);
        s.validate()?;
        let detail = json!({ "look": label, "mode": mode.name(), "settings": s,
                "particles": n });
        let suffix = if lanes > 1 {
            format!("-lanes-{lanes}")
        } else {
            String::new()
        };
        shots.push(Shot {
            variant: format!(
                "{}-{}{suffix}",
                material.as_str(),
                mode.name().replace(' ', "-")
            ),
            settings: s,
            centers: &buf,
            centers_key: format!("thesis {n}"),
            n: n as u32,
            cam,
            detail,
        });
        which.push((k, label, mode, lanes));
    }
    steps.start("every look and mode, interleaved");
    let timed = time_shots(ctx, env, &opts, &shots)?;
    steps.tick();
    let mut out: Vec<Vec<Cell>> = LOOKS.iter().map(|_| Vec::new()).collect();
    let mut laned = Vec::new();
    for ((t, shot), (k, label, mode, lanes)) in timed.iter().zip(&shots).zip(which) {
        let (st, after) = (&t.sized, &t.after);
        if after.budget_pixels > 0 || after.overflow > 0 {
            return Err(Error::Param(format!(
                "lists: {label} {}: {} pixels past the loop budget, {} entries overflowed",
                mode.name(),
                after.budget_pixels,
                after.overflow
            )));
        }
        let s = &shot.settings;
        let px = s.pixels() as f64;
        let (st_px, ev_px, _) = after.march.per_pixel(s.pixels());
        let bytes = 16.0 * n as f64 + 4.0 * px + 2.0 * st.list_bytes as f64;
        let passes = (t.row.passes.iter())
            .filter_map(|(k, v)| Some((k.strip_prefix("render/")?, v.median)))
            .map(|(k, v)| format!("{k} {v:.2}"))
            .collect::<Vec<_>>()
            .join(", ");
        let cell = Cell {
            mode,
            ms: t.row.main.median,
            est: t.row.estimate().unwrap_or_default(),
            passes,
            list_mb: st.list_bytes as f64 / 1e6,
            steps: st_px,
            evals: ev_px,
            floor: floor.ms(bytes, after.march.evaluations as f64),
            lanes,
            serial: after.march.serial_max,
        };
        match lanes {
            1 => out[k].push(cell),
            _ => laned.push(cell),
        }
    }
    Ok((out, laned))
}

/// Frames the character plays per mode.
fn character_frames(env: &Env) -> u64 {
    if env.quick {
        8
    } else {
        60
    }
}

/// The character scene's median `render` ms per mode.
fn character(env: &Env, steps: &mut Steps) -> Result<Vec<(Mode, f64)>> {
    let frames = character_frames(env);
    let mut out = Vec::new();
    for mode in CHARACTER {
        steps.start(&format!("character {}", mode.name()));
        let mut sw = env.switches.clone();
        sw.common.quiet = true;
        sw.view.render = Some(RenderKind::Metaballs);
        sw.metaball.list = Some(mode.0);
        if mode.0 == S {
            sw.metaball.list_sort = Some(crate::config::OnOff::On);
            sw.metaball.build = Some(mode.2);
        }
        sw.metaball.tile = (mode.2 == C).then_some(mode.3);
        sw.metaball.march = Some(mode.4);
        let dir = env
            .runs(Experiment::Lists)
            .join(format!("character-{}", mode.name().replace(' ', "-")));
        let opts = crate::run::RunOptions {
            scene: "character".into(),
            frames: Some(frames),
            out: dir.clone(),
            save_every: frames - 1,
            switches: sw,
        };
        let ms = crate::run::run(&opts)?
            .summary
            .pass_median(crate::render::SCOPE)?;
        out.push((*mode, ms));
        steps.tick();
    }
    Ok(out)
}

pub fn lists(ctx: &crate::gpu::Context, env: &mut Env) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let glass = MODES.iter().filter(|m| glass_mode(m)).count();
    let total = (MODES.len() + glass + CHARACTER.len()) as u64;
    let mut steps = Steps::new("lists", total, env.switches.common.quiet);
    let (cells, laned) = thesis_frame(ctx, env, &mut steps)?;
    let demo = character(env, &mut steps)?;
    steps.finish();
    let (w, h, n) = (env.width, env.height, env.particles);
    let mut md = format!(
        "# Metaball lists: modes, builds and marches\n\n\
         The thesis frame (the walker filled with {n} particles, {w}x{h}, Wyvill, T 0.9, \
         R 0.04, I 2), rendered alone per mode: GPU median of the `render` scope and its \
         passes; list MB: the list structures' bytes; steps and evaluations per pixel: the \
         march's counters; floor: the frame's least traffic (centres read, picture written, \
         lists written and read once) over the copy bandwidth measured in this run, or its \
         evaluations ({} FLOPs each) over the FMA rate measured in this run, whichever is \
         larger. Glass runs the sorted lists and tiles of 8 and 16 only.\n",
        crate::bench::floor::FLOPS_PER_EVAL
    );
    let mut csv =
        String::from("look,mode,render_ms,passes,list_mb,steps_px,evals_px,floor_ms,x_floor\n");
    for ((label, _, _, _), row) in LOOKS.iter().zip(&cells) {
        md.push_str(&format!(
            "\n## {label}\n\n| mode | render ms | x first row | passes (ms) | list MB | steps/px | evals/px | serial max | floor ms | x floor |\n|---|---|---|---|---|---|---|---|---|---|\n"
        ));
        let sb = row.first().map_or(f64::NAN, |c| c.ms);
        for c in row {
            md.push_str(&format!(
                "| {} | {:.2} | {:.2} | {} | {:.2} | {:.2} | {:.0} | {} | {:.4} | {:.0} |\n",
                c.mode.name(),
                c.ms,
                sb / c.ms,
                c.passes,
                c.list_mb,
                c.steps,
                c.evals,
                c.serial,
                c.floor,
                c.ms / c.floor
            ));
            csv.push_str(&format!(
                "\"{label}\",{},{:.4},\"{}\",{:.4},{:.3},{:.2},{:.5},{:.2}\n",
                c.mode.name(),
                c.ms,
                c.passes,
                c.list_mb,
                c.steps,
                c.evals,
                c.floor,
                c.ms / c.floor
            ));
        }
    }
    md.push_str(&laned_md(&cells[1], &laned));
    let base_ms = demo.first().map_or(f64::NAN, |d| d.1);
    md.push_str(&format!(
        "\n## The liquid character (`fluidform run --scene character`, {} frames, tinted)\n\n| mode | render ms | x default |\n|---|---|---|\n",
        character_frames(env)
    ));
    for (mode, ms) in &demo {
        md.push_str(&format!(
            "| {} | {ms:.2} | {:.2} |\n",
            mode.name(),
            base_ms / ms
        ));
        csv.push_str(&format!("character,{},{ms:.4},,,,,,\n", mode.name()));
    }
    // Short bar labels: S = S-buffer, /c = built in compute, L = the Lipschitz march.
    let short = |m: &Mode| {
        (m.name().replace("sbuffer", "S").replace("-compute", "/c"))
            .replace("-sorted", " sorted")
            .replace(" lipschitz", " L")
    };
    let labels: Vec<String> = MODES.iter().map(short).collect();
    let series: Vec<(String, Vec<Option<f64>>)> = (LOOKS.iter().zip(&cells))
        .map(|((l, _, _, _), row)| {
            let at = |m: &Mode| row.iter().find(|c| c.mode == *m).map(|c| c.ms);
            (l.to_string(), MODES.iter().map(at).collect())
        })
        .collect();
    let png = env.out.join("lists.png");
    crate::bench::plot::grouped_bars(
        &png,
        "Metaball list modes, thesis frame",
        &format!("{}, {}", env.meta.device, env.meta.date),
        &labels,
        &series,
        "render ms per frame",
    )?;
    md.push_str("\n![render ms per mode](lists.png)\n\nBars: S = S-buffer, /c = built in compute, L = `--march lipschitz`.\n");
    let mut found = findings(&cells, &demo);
    found.push(parallel_march(&cells[1], &laned));
    let p_csv = env.out.join("lists.csv");
    write(&p_csv, &csv)?;
    let p_md = super::finish_md(env, Experiment::Lists, md, &found)?;
    Ok((vec![p_csv, p_md, png], found))
}

fn findings(cells: &[Vec<Cell>], demo: &[(Mode, f64)]) -> Vec<Finding> {
    let cell = |row: &'_ [Cell], m: Mode| row.iter().find(|c| c.mode == m).cloned();
    let fixed =
        |row: &[Cell]| -> Vec<Cell> { row.iter().filter(|c| c.mode.4 == FIXED).cloned().collect() };
    let best = |v: &[Cell]| v.iter().cloned().min_by(|a, b| a.ms.total_cmp(&b.ms));
    // Timings compare beyond their 95% intervals (a flagged cell decides nothing).
    let less = |a: &Cell, b: &Cell| Verdict::faster(&a.est, &b.est);
    let (phong, glass) = (&cells[0], &cells[1]);
    let compute = best(
        &fixed(phong)
            .into_iter()
            .filter(|c| c.mode.0 == S && c.mode.2 == C)
            .collect::<Vec<_>>(),
    );
    let mut found = Vec::new();
    found.push(match (compute, cell(phong, MODES[0])) {
        (Some(c), Some(a)) => Finding::new(
            COMPUTE_BEATS_ABUFFER,
            less(&c, &a),
            format!(
                "{}: {}, A-buffer {} ({:.2}x)",
                c.mode.name(),
                c.est.text(),
                a.est.text(),
                a.ms / c.ms
            ),
        ),
        _ => Finding::new(COMPUTE_BEATS_ABUFFER, Verdict::NotMeasured, String::new()),
    });
    let (mut vs, mut ev) = (Vec::new(), Vec::new());
    for ((label, _, _, _), row) in LOOKS.iter().zip(cells) {
        for sorted in [false, true] {
            let (Some(r), Some(c)) = (
                cell(row, Mode(S, sorted, R, 16, FIXED)),
                cell(row, Mode(S, sorted, C, 16, FIXED)),
            ) else {
                continue;
            };
            // At least as fast: refuted only where compute is slower beyond the intervals.
            let v = match less(&r, &c) {
                Verdict::Confirmed => Verdict::Refuted,
                Verdict::Refuted => Verdict::Confirmed,
                v => v,
            };
            vs.push(v);
            ev.push(format!(
                "{label} {}: {:.2}x ({}, raster {}, compute {})",
                if sorted { "sorted" } else { "unsorted" },
                r.ms / c.ms,
                v.word(),
                r.est.text(),
                c.est.text()
            ));
        }
    }
    found.push(Finding::new(
        COMPUTE_AS_FAST,
        Verdict::all(vs),
        format!("raster ms / compute ms: {}", ev.join("; ")),
    ));
    let (mut vs, mut ev) = (Vec::new(), Vec::new());
    for ((label, _, _, _), row) in LOOKS.iter().zip(cells) {
        let f = fixed(row);
        let (lists, tiles): (Vec<Cell>, Vec<Cell>) =
            f.iter().cloned().partition(|c| c.mode.per_pixel());
        let (tiles, lists) = (best(&tiles), best(&lists));
        if let (Some(t), Some(l)) = (tiles, lists) {
            let v = less(&t, &l);
            vs.push(v);
            ev.push(format!(
                "{label} ({}): {} {}, best list {} {}",
                v.word(),
                t.mode.name(),
                t.est.text(),
                l.mode.name(),
                l.est.text()
            ));
        }
    }
    found.push(Finding::new(
        TILES_BEAT_LISTS,
        Verdict::all(vs),
        ev.join("; "),
    ));
    let (mut holds, mut ev) = (true, Vec::new());
    for ((label, _, _, _), row) in LOOKS.iter().zip(cells) {
        for c in row.iter().filter(|c| c.mode.4 == LIP) {
            let m = c.mode;
            if let Some(f) = row
                .iter()
                .find(|f| f.mode == Mode(m.0, m.1, m.2, m.3, FIXED))
            {
                holds &= c.steps < f.steps;
                ev.push(format!(
                    "{label} {}: {:.3} -> {:.3} steps/px",
                    f.mode.name(),
                    f.steps,
                    c.steps
                ));
            }
        }
    }
    found.push(Finding::new(
        LIPSCHITZ_FEWER,
        Verdict::of(holds),
        ev.join("; "),
    ));
    for (claim, row, reference) in [(BEST_PHONG, phong, MODES[1]), (BEST_GLASS, glass, MODES[2])] {
        found.push(match (best(row), cell(row, reference)) {
            (Some(t), Some(r)) => Finding::new(
                claim,
                Verdict::speedup_at_least(&r.est, &t.est, 2.0),
                format!(
                    "{}: {} against {} {} ({:.2}x)",
                    t.mode.name(),
                    t.est.text(),
                    reference.name(),
                    r.est.text(),
                    r.ms / t.ms
                ),
            ),
            _ => Finding::new(claim, Verdict::NotMeasured, String::new()),
        });
    }
    let d0 = demo.first().map_or(f64::NAN, |d| d.1);
    let fastest = demo.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1));
    found.push(match fastest {
        Some((m, t)) => Finding::new(
            DEMO_FASTER,
            Verdict::of(d0 / t >= 2.0),
            format!(
                "{}: {t:.2} ms against the default's {d0:.2} ms ({:.2}x)",
                m.name(),
                d0 / t
            ),
        ),
        None => Finding::new(DEMO_FASTER, Verdict::NotMeasured, String::new()),
    });
    found
}

/// The glass section of rays marched by several lanes: [`LANED`]'s serial row, then each
/// lane count's, with the longest serial chain.
fn laned_md(glass: &[Cell], laned: &[Cell]) -> String {
    let Some(serial) = glass.iter().find(|c| c.mode == LANED) else {
        return String::new();
    };
    let mut md = format!(
        "\n## Glass, depth 3: rays marched by several lanes\n\n{}: one invocation a ray, or \
         `--ray-lanes N` lanes of a subgroup (each a grid sample: the same hits). serial \
         max: the most field evaluations one invocation made in series.\n\n\
         | ray lanes | render ms | x serial | serial max |\n|---|---|---|---|\n",
        LANED.name()
    );
    for c in std::iter::once(serial).chain(laned) {
        md.push_str(&format!(
            "| {} | {:.2} | {:.2} | {} |\n",
            c.lanes,
            c.ms,
            serial.ms / c.ms,
            c.serial
        ));
    }
    md
}

/// [`PARALLEL_MARCH`]: the widest lane count against the serial march, beyond the
/// intervals (not measured where the device's subgroup holds no lanes).
fn parallel_march(glass: &[Cell], laned: &[Cell]) -> Finding {
    let serial = glass.iter().find(|c| c.mode == LANED);
    let widest = laned.iter().max_by_key(|c| c.lanes);
    let (Some(s), Some(w)) = (serial, widest) else {
        return Finding::new(PARALLEL_MARCH, Verdict::NotMeasured, String::new());
    };
    let each: Vec<String> = laned
        .iter()
        .map(|c| format!("{} lanes {} ({:.2}x)", c.lanes, c.est.text(), s.ms / c.ms))
        .collect();
    Finding::new(
        PARALLEL_MARCH,
        Verdict::speedup_at_least(&s.est, &w.est, 4.0),
        format!(
            "{}: serial {} (serial max {}), {}; serial max at {} lanes {}",
            LANED.name(),
            s.est.text(),
            s.serial,
            each.join(", "),
            w.lanes,
            w.serial
        ),
    )
}
