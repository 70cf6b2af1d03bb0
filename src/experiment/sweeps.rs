//! The experiments over N or time: seed 002's figure 9 (counting grid against hash +
//! bitonic), the thesis's adaptive-pressure fill test (figures 12/13), and our own
//! scaling sweep of the SPH step and the renderer.
use super::findings::{self, Finding, Verdict};
use super::{write, Env, Experiment, Steps};
use crate::bench::{Bench, Measurer, Row};
use crate::error::{Error, Result};
use crate::gpu::{Context, Guard};
use crate::kinds::{Neighbors, SortAlgo};
use crate::render::ListKind;
use std::path::PathBuf;

fn per_particle_ns(r: &Row) -> f64 {
    r.main.median * 1e6 / r.n.max(1) as f64
}

/// CSV of sweep rows: kind, variant, n, reps, median/min/max ms, ns per particle.
fn csv(rows: &[(String, Row)]) -> String {
    let mut s = String::from("kind,variant,n,reps,median_ms,min_ms,max_ms,fps,ns_per_particle\n");
    for (kind, r) in rows {
        s.push_str(&format!(
            "{kind},{},{},{},{:.4},{:.4},{:.4},{:.3},{:.3}\n",
            r.variant,
            r.n,
            r.reps,
            r.main.median,
            r.main.min,
            r.main.max,
            1000.0 / r.main.median,
            per_particle_ns(r)
        ));
    }
    s
}

/// Markdown rows: variant, N, reps, median [95% interval] ms, fps, ns per particle.
fn md_rows(rows: &[&Row]) -> String {
    let mut s = String::from(
        "| variant | N | reps | median ms [95% interval] | fps | ns per particle |\n|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {:.3} [{:.3}, {:.3}]{} | {:.2} | {:.1} |\n",
            r.variant,
            r.n,
            r.reps,
            r.main.median,
            r.interval.map_or(r.main.min, |i| i.lo),
            r.interval.map_or(r.main.max, |i| i.hi),
            if r.flagged { " flagged" } else { "" },
            1000.0 / r.main.median,
            per_particle_ns(r)
        ));
    }
    s
}

/// `a` faster than `b` beyond their intervals (inconclusive where either was flagged or
/// has none).
fn row_less(a: &Row, b: &Row) -> Verdict {
    match (a.estimate(), b.estimate()) {
        (Some(x), Some(y)) => Verdict::faster(&x, &y),
        _ => Verdict::Inconclusive,
    }
}

/// Grid against hash at each N (`a` and `b` variants), and the grid's growth of cost per
/// particle from its cheapest N to its largest.
fn grid_findings(rows: &[&Row], a: &str, b: &str, what: &str) -> Vec<Finding> {
    let of = |v: &str| -> Vec<&Row> { rows.iter().copied().filter(|r| r.variant == v).collect() };
    let (ga, hb) = (of(a), of(b));
    let mut wins = Vec::new();
    for g in &ga {
        if let Some(h) = hb.iter().find(|h| h.n == g.n) {
            wins.push((g.n, h.main.median / g.main.median, row_less(g, h)));
        }
    }
    let mut out = Vec::new();
    out.push(match wins.is_empty() {
        true => Finding::new(
            findings::GRID_BEATS,
            Verdict::NotMeasured,
            format!("{what}: no N with both"),
        ),
        false => Finding::new(
            findings::GRID_BEATS,
            Verdict::all(wins.iter().map(|w| w.2)),
            format!(
                "{what}: {b} / {a} time {}",
                wins.iter()
                    .map(|(n, r, v)| format!("{r:.2}x at N = {n} ({})", v.word()))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ),
    });
    if ga.len() >= 2 {
        let last = ga.last().expect("two rows");
        let best = ga
            .iter()
            .map(|r| per_particle_ns(r))
            .fold(f64::INFINITY, f64::min);
        let growth = per_particle_ns(last) / best;
        out.push(Finding::new(
            findings::GRID_LINEAR,
            Verdict::of(growth <= 1.5),
            format!(
                "{what}: {a} cost per particle at N = {} is {growth:.2}x its lowest over N = {}..{} \
                 (linear: at most 1.5x); {}",
                last.n,
                ga[0].n,
                last.n,
                ga.iter()
                    .map(|r| format!("{:.0} ns at {}", per_particle_ns(r), r.n))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    out
}

pub fn fig9(ctx: &Context, env: &mut Env) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let counts: Vec<u32> = match env.quick {
        true => vec![8 << 10, 16 << 10],
        false => crate::bench::emission::COUNTS.to_vec(),
    };
    let mut opts = env.bench_options(Measurer::Bench(Bench::Emission), Experiment::Fig9);
    let mut steps = Steps::new("fig9", counts.len() as u64, env.switches.common.quiet);
    let mut rows = Vec::new();
    for &n in &counts {
        steps.start(&format!("N = {n}"));
        opts.counts = vec![n];
        rows.extend(crate::bench::emission::emission(ctx, &opts)?);
        steps.tick();
    }
    steps.finish();
    let refs: Vec<&Row> = rows.iter().collect();
    let found = grid_findings(&refs, "grid/counting", "hash/bitonic", "emitting frame");
    let tagged: Vec<(String, Row)> = rows
        .iter()
        .map(|r| ("frame".to_string(), r.clone()))
        .collect();
    let p_csv = env.out.join("fig9.csv");
    write(&p_csv, &csv(&tagged))?;
    let labels: Vec<String> = refs
        .iter()
        .filter(|r| r.variant == "grid/counting")
        .map(|r| r.n.to_string())
        .collect();
    let series: Vec<(String, Vec<Option<f64>>)> = ["grid/counting", "hash/bitonic"]
        .iter()
        .map(|v| {
            let vals = refs
                .iter()
                .filter(|r| r.variant == *v)
                .map(|r| Some(1000.0 / r.main.median))
                .collect();
            (v.to_string(), vals)
        })
        .collect();
    let png = env.out.join("fig9.png");
    crate::bench::plot::grouped_bars(
        &png,
        "Seed 002 figure 9: emitting frame rate against N",
        &format!("{}, {}", env.meta.device, env.meta.date),
        &labels,
        &series,
        "frames per second",
    )?;
    let mut md = String::from(
        "# Seed 002, figure 9: frame rate against particle count, counting grid vs hash + bitonic\n\n\
         The paper's figure plots frames per second at 8K, 16K, 32K and 64K particles on a \
         GeForce GT240M and a GTX 590 with the counting grid and with hashing + bitonic sort; \
         its text gives no values, only that the grid is O(N) and faster. Ours: `bench \
         emission`'s scene (the game room, a floor pool of N emitter slots kept alive by \
         births), one frame = skin + RenderToUV (512x512) + one step with emit; medians of \
         GPU frame time after warm-up.\n\n",
    );
    md.push_str(&md_rows(&refs));
    md.push_str("\n| N | grid fps | hash fps | grid speed-up |\n|---|---|---|---|\n");
    for g in refs.iter().filter(|r| r.variant == "grid/counting") {
        let n = g.n;
        let h = refs
            .iter()
            .find(|r| r.variant == "hash/bitonic" && r.n == n)
            .map(|r| 1000.0 / r.main.median);
        if let (g, Some(h)) = (1000.0 / g.main.median, h) {
            md.push_str(&format!("| {n} | {g:.2} | {h:.2} | {:.2}x |\n", g / h));
        }
    }
    md.push_str("\n![frames per second against N](fig9.png)\n");
    let p_md = super::finish_md(env, Experiment::Fig9, md, &found)?;
    Ok((vec![p_csv, p_md, png], found))
}

pub fn scaling(ctx: &Context, env: &mut Env) -> Result<(Vec<PathBuf>, Vec<Finding>)> {
    let (sph_counts, render_factors, cap_ms): (Vec<u32>, Vec<f64>, f64) = match env.quick {
        true => (vec![1 << 10, 4 << 10], vec![0.5, 1.0, 2.0], 300.0),
        false => (
            vec![
                1 << 10,
                4 << 10,
                16 << 10,
                64 << 10,
                256 << 10,
                1 << 20,
                4 << 20,
            ],
            vec![0.5, 1.0, 2.0, 4.0, 8.0, 16.0],
            4000.0,
        ),
    };
    let strategies = [
        (Neighbors::Grid, SortAlgo::Counting),
        (Neighbors::Hash, SortAlgo::Bitonic),
        (Neighbors::Morton, SortAlgo::OddEven),
    ];
    let lists = [ListKind::None, ListKind::Abuffer, ListKind::Sbuffer];
    let total = strategies.len() * sph_counts.len() + lists.len() * render_factors.len();
    let mut sw = Sweep {
        steps: Steps::new("scaling", total as u64, env.switches.common.quiet),
        rows: Vec::new(),
        stops: Vec::new(),
        cap_ms,
    };
    let mut opts = env.bench_options(Measurer::Bench(Bench::Sph), Experiment::Scaling);
    for (strategy, sort) in strategies {
        scaling_sph(ctx, &mut opts, (strategy, sort), &sph_counts, &mut sw)?;
    }
    // Render: the thesis scene's walker and camera filled with more and more particles.
    let cam = env.scene(ctx)?.camera;
    let ropts = env.bench_options(Measurer::Bench(Bench::Render), Experiment::Scaling);
    for list in lists {
        scaling_render(ctx, env, &ropts, list, &render_factors, &cam, &mut sw)?;
    }
    sw.steps.finish();
    let (rows, stops) = (sw.rows, sw.stops);
    let sph: Vec<&Row> = rows
        .iter()
        .filter(|(k, _)| k == "sph")
        .map(|(_, r)| r)
        .collect();
    let render: Vec<&Row> = rows
        .iter()
        .filter(|(k, _)| k == "render")
        .map(|(_, r)| r)
        .collect();
    let found = scaling_findings(&sph, &render, &lists);
    let p_csv = env.out.join("scaling.csv");
    write(&p_csv, &csv(&rows))?;
    let png = env.out.join("scaling.png");
    let plot_rows: Vec<Row> = rows
        .iter()
        .map(|(k, r)| Row {
            variant: format!("{k} {}", r.variant),
            ..r.clone()
        })
        .collect();
    crate::bench::plot::sweep(
        &png,
        "scaling: SPH step and render frame",
        "GPU",
        &env.meta.device,
        &plot_rows,
    )?;
    let mut md = String::from(
        "# Scaling: SPH step and metaball frame from 1K particles up\n\n\
         Ours (no paper table). SPH: one step of the dam break scaled to N (`bench sph`), per \
         neighbour strategy. Render: the thesis scene's walker and camera (tables 2-8) filled \
         with N particles at a shrinking spacing, Phong at the table size, per list. A series \
         stops where the device cannot hold N or a repetition exceeds the time cap.\n\n## SPH step\n\n",
    );
    md.push_str(&md_rows(&sph));
    md.push_str("\n## Render frame\n\n");
    md.push_str(&md_rows(&render));
    if !stops.is_empty() {
        md.push_str("\nSeries stopped:\n\n");
        for s in &stops {
            md.push_str(&format!("- {s}\n"));
        }
    }
    md.push_str("\n![cost per particle against N](scaling.png)\n");
    let p_md = super::finish_md(env, Experiment::Scaling, md, &found)?;
    Ok((vec![p_csv, p_md, png], found))
}

/// The scaling sweep's state: progress, rows by kind, why series stopped, the time cap.
struct Sweep {
    steps: Steps,
    rows: Vec<(String, Row)>,
    stops: Vec<String>,
    cap_ms: f64,
}

/// One neighbour strategy's SPH series, stopped at the device's size or the time cap.
fn scaling_sph(
    ctx: &Context,
    opts: &mut crate::bench::BenchOptions,
    (strategy, sort): (Neighbors, SortAlgo),
    sph_counts: &[u32],
    sw: &mut Sweep,
) -> Result<()> {
    let limit = crate::sph::solver::MAX_PARTICLES
        .min(ctx.info.device_local_bytes / 2 / crate::sph::solver::BYTES_PER_PARTICLE);
    let cap = sw.cap_ms;
    opts.switches.search.neighbors = Some(strategy);
    opts.switches.sorting.sort = Some(sort);
    let mut stopped = false;
    for &n in sph_counts {
        sw.steps
            .start(&format!("sph {} N = {n}", strategy.as_str()));
        if !stopped && n as u64 > limit {
            sw.stops.push(format!(
                "sph {}: N = {n} exceeds what the device holds ({limit})",
                strategy.as_str()
            ));
            stopped = true;
        }
        if !stopped {
            opts.counts = vec![n];
            let r = crate::bench::sph::steps(ctx, opts)?;
            for row in r {
                if row.main.median > sw.cap_ms {
                    sw.stops.push(format!(
                        "sph {}: stopped after N = {} ({:.0} ms a step, over the {cap:.0} ms cap)",
                        row.variant, row.n, row.main.median
                    ));
                    stopped = true;
                }
                sw.rows.push(("sph".into(), row));
            }
        }
        sw.steps.tick();
    }
    Ok(())
}

/// One list's render series: the thesis scene's walker and camera with more particles.
fn scaling_render(
    ctx: &Context,
    env: &mut Env,
    ropts: &crate::bench::BenchOptions,
    list: ListKind,
    render_factors: &[f64],
    cam: &crate::render::Camera,
    sw: &mut Sweep,
) -> Result<()> {
    let (base_n, seed) = (env.particles, env.switches.common.seed);
    let cap = sw.cap_ms;
    let mut stopped = false;
    for &f in render_factors {
        let n = (base_n as f64 * f).round() as usize;
        sw.steps.start(&format!("render {} N = {n}", list.as_str()));
        if !stopped {
            match render_row(ctx, env, ropts, list, n, seed, cam) {
                Ok(row) => {
                    if row.main.median > sw.cap_ms {
                        sw.stops.push(format!(
                            "render {}: stopped after N = {n} ({:.0} ms a frame, over the {cap:.0} ms cap)",
                            list.as_str(),
                            row.main.median
                        ));
                        stopped = true;
                    }
                    sw.rows.push(("render".into(), row));
                }
                Err(Error::Memory(m)) => {
                    sw.stops.push(format!(
                        "render {}: N = {n} does not fit: {m}",
                        list.as_str()
                    ));
                    stopped = true;
                }
                Err(e) => return Err(e),
            }
        }
        sw.steps.tick();
    }
    Ok(())
}

/// Findings of the scaling sweep: grid against hash, and render cost rising with N.
fn scaling_findings(sph: &[&Row], render: &[&Row], lists: &[ListKind]) -> Vec<Finding> {
    let mut found = grid_findings(sph, "grid/counting", "hash/bitonic", "SPH step");
    let mut fails = Vec::new();
    let mut verdicts = Vec::new();
    for list in lists {
        let rows: Vec<&Row> = render
            .iter()
            .copied()
            .filter(|r| r.variant == list.as_str())
            .collect();
        let v = Verdict::all(rows.windows(2).map(|w| row_less(w[0], w[1])));
        if v != Verdict::Confirmed {
            fails.push(format!("{} ({})", list.as_str(), v.word()));
        }
        verdicts.push(v);
    }
    found.push(Finding::new(
        "cost rises with the particle count N",
        Verdict::all(verdicts),
        format!(
            "render frame time over N = {}..{} rises for {} of 3 lists{}",
            render.first().map(|r| r.n).unwrap_or(0),
            render.iter().map(|r| r.n).max().unwrap_or(0),
            3 - fails.len(),
            match fails.is_empty() {
                true => String::new(),
                false => format!(" (not for {})", fails.join(", ")),
            }
        ),
    ));
    found
}

/// One render configuration of the scaling sweep: the thesis walker with `n` particles.
fn render_row(
    ctx: &Context,
    env: &mut Env,
    opts: &crate::bench::BenchOptions,
    list: ListKind,
    n: usize,
    seed: u64,
    cam: &crate::render::Camera,
) -> Result<Row> {
    let centers = env.scene(ctx)?.with_particles(n, seed)?;
    let mut s = super::measure::base(env.width, env.height)?;
    s.list = list;
    let mut buf = Guard::new(ctx, ctx.storage_buffer("scaling centers", (n * 16) as u64)?);
    ctx.upload(&mut buf, 0, &centers)?;
    let detail = serde_json::json!({ "settings": s, "particles": n });
    // One N at a time (the series stops at the time cap), each under the protocol.
    let shot = super::shots::Shot {
        variant: list.as_str().to_string(),
        settings: s,
        centers: &buf,
        centers_key: format!("scaling {n} seed {seed}"),
        n: n as u32,
        cam: *cam,
        detail,
    };
    let t = super::shots::time_shots(ctx, env, opts, std::slice::from_ref(&shot))?;
    let mut row = t.into_iter().next().expect("one shot").row;
    row.variant = list.as_str();
    Ok(row)
}
