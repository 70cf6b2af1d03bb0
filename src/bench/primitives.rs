//! Benchmarks of the GPU primitives: scan (against a buffer copy), sorts, neighbours.
use super::protocol::{self, Case};
use super::{counts, BenchOptions, Row};
use crate::error::{Error, Result};
use crate::gpu::vk;
use crate::gpu::Open;
use crate::gpu::{Buffer, Context, Guard, ScopeKey};
use crate::kinds::{Neighbors, SortAlgo};
use crate::primitives::counting::{CountingBuffers, CountingSort};
use crate::primitives::neighbors::{default_sort, GridSpec, NeighborSearch};
use crate::primitives::scan::{ScanKind, ScanPass, ScanVariant};
use crate::primitives::sort::{Network, NetworkSort};
use rand::{Rng, SeedableRng};
use serde_json::json;

const RESTORE_SCOPE: crate::gpu::ScopeName = crate::gpu::ScopeName::new("restore");

/// The primitives' timestamp scopes, opened here around each primitive.
const SCAN: ScopeKey = ScopeKey::new("scan");
const SORT: ScopeKey = ScopeKey::new("sort");
const NEIGHBORS: ScopeKey = ScopeKey::new("neighbors");

fn copy(ctx: &Context, cmd: vk::CommandBuffer, src: &Buffer, dst: &Buffer, bytes: u64) {
    ctx.copy(cmd, src, 0, dst, 0, bytes);
}

fn upload(ctx: &Context, name: &str, data: &[u32]) -> Result<Buffer> {
    let mut b = ctx.storage_buffer(name, (data.len().max(1) * 4) as u64)?;
    ctx.upload(&mut b, 0, data)?;
    Ok(b)
}

/// Exclusive scan of N u32 beside a plain copy of the same bytes, in the same frame.
pub fn scan(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let mut ns = counts(opts);
    if opts.switches.common.particles.is_none() {
        ns.push(16 << 20);
    }
    let pass = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
    let variant = if pass.uses_subgroups {
        "scan-subgroup"
    } else {
        "scan-shared"
    };
    // Every size's buffers first: the protocol interleaves them.
    let mut sets = Vec::new();
    for &n in &ns {
        let mut rng = rand_pcg::Pcg32::seed_from_u64(opts.switches.common.seed);
        let data: Vec<u32> = (0..n).map(|_| rng.random_range(0..16)).collect();
        sets.push((
            n,
            Guard::new(ctx, upload(ctx, "bench scan input", &data)?),
            Guard::new(ctx, ctx.storage_buffer("bench scan output", n as u64 * 4)?),
            Guard::new(ctx, ctx.storage_buffer("bench copy output", n as u64 * 4)?),
            Guard::new(ctx, pass.scratch(ctx, n as u64)?),
        ));
    }
    let pass = &*pass;
    let cases = sets
        .iter()
        .map(|(n, input, output, copied, scratch)| {
            let (n, bytes) = (*n as u64, *n as u64 * 4);
            Case::new(variant, n, SCAN, json!({}), move |prof, cmd| {
                {
                    let _scope = prof.open(ctx, cmd, SCAN.scope());
                    pass.record(ctx, cmd, input, output, n, ScanKind::Exclusive, scratch)?;
                }
                {
                    let _scope = prof.open(ctx, cmd, super::floor::COPY.scope());
                    copy(ctx, cmd, input, copied, bytes);
                }
                Ok(())
            })
        })
        .collect();
    let mut rows = protocol::run(ctx, opts, cases)?;
    for row in &mut rows {
        let bytes = row.n * 4;
        let copy_ms = row.pass(super::floor::COPY)?.median;
        // Both move 2 * bytes (read + write); bandwidth = 2 * bytes / time.
        let gbs = |ms: f64| 2.0 * bytes as f64 / (ms * 1e6);
        row.extra = vec![
            ("scan GB/s".into(), format!("{:.2}", gbs(row.main.median))),
            ("copy GB/s".into(), format!("{:.2}", gbs(copy_ms))),
            (
                "scan/copy bandwidth".into(),
                format!("{:.0}%", 100.0 * copy_ms / row.main.median),
            ),
        ];
    }
    Ok(rows)
}

/// Grid-cell keys of N random particles, about four per cell (the neighbour-search load).
fn cell_keys(n: u32, seed: u64) -> (Vec<u32>, u32) {
    let side = ((n as f64 / 4.0).cbrt().round() as u32).max(1);
    let cells = side * side * side;
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let keys = (0..n).map(|_| rng.random_range(0..cells)).collect();
    (keys, cells)
}

/// One sort configuration's buffers: pristine keys and values, the working copies, the
/// counting sort's outputs.
struct SortSet<'c> {
    algo: SortAlgo,
    n: u32,
    cells: u32,
    bufs: Guard<'c, Vec<Buffer>>,
    cb: Guard<'c, CountingBuffers>,
}

pub fn sort(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let algos = match opts.switches.sorting.sort {
        Some(SortAlgo::None) => return Err(Error::Param(
            "bench sort --sort none: nothing to measure (none applies to particle-system sprites)"
                .into(),
        )),
        Some(s) => vec![s],
        None => vec![SortAlgo::OddEven, SortAlgo::Bitonic, SortAlgo::Counting],
    };
    let scan = Guard::new(ctx, ScanPass::new(ctx, ScanVariant::Auto)?);
    let counting = Guard::new(ctx, CountingSort::new(ctx)?);
    let odd_even = Guard::new(ctx, NetworkSort::new(ctx, Network::OddEven)?);
    let bitonic = Guard::new(ctx, NetworkSort::new(ctx, Network::Bitonic)?);
    let mut sets = Vec::new();
    for &algo in &algos {
        for n in counts(opts) {
            let (keys, cells) = cell_keys(n, opts.switches.common.seed);
            let vals: Vec<u32> = (0..n).collect();
            let bytes = n as u64 * 4;
            let mut bufs = Guard::new(ctx, Vec::new());
            bufs.push(upload(ctx, "bench pristine keys", &keys)?);
            bufs.push(upload(ctx, "bench pristine values", &vals)?);
            for name in ["keys", "values", "sorted keys", "sorted values"] {
                bufs.push(ctx.storage_buffer(&format!("bench {name}"), bytes)?);
            }
            let cb = Guard::new(ctx, CountingBuffers::new(ctx, &scan, n as u64, cells)?);
            sets.push(SortSet {
                algo,
                n,
                cells,
                bufs,
                cb,
            });
        }
    }
    let (scan, counting) = (&*scan, &*counting);
    let (odd_even, bitonic) = (&*odd_even, &*bitonic);
    let cases =
        sets.iter()
            .map(|s| {
                let network = match s.algo {
                    SortAlgo::OddEven => Some(odd_even),
                    SortAlgo::Bitonic => Some(bitonic),
                    SortAlgo::Counting | SortAlgo::None => None,
                };
                let (n, bytes) = (s.n as u64, s.n as u64 * 4);
                let b = &s.bufs;
                let cb = &*s.cb;
                let detail = json!({ "cells": s.cells, "keys": "uniform random cell ids" });
                Case::new(s.algo.as_str(), n, SORT, detail, move |prof, cmd| {
                    {
                        let _scope = prof.open(ctx, cmd, RESTORE_SCOPE);
                        copy(ctx, cmd, &b[0], &b[2], bytes);
                        copy(ctx, cmd, &b[1], &b[3], bytes);
                    }
                    {
                        let _scope = prof.open(ctx, cmd, SORT.scope());
                        match network {
                            Some(s) => {
                                s.record(ctx, cmd, &b[2], &b[3], n)?;
                            }
                            None => counting
                                .record(ctx, cmd, scan, cb, &b[2], &b[3], &b[4], &b[5], n)?,
                        }
                    }
                    Ok(())
                })
            })
            .collect();
    protocol::run(ctx, opts, cases)
}

/// Radius giving about `k` neighbours for n uniform points in the unit cube.
pub fn radius_for(n: u32, k: f64) -> f32 {
    (k / (n as f64 * 4.0 / 3.0 * std::f64::consts::PI)).cbrt() as f32
}

/// One neighbour-search configuration: its search, points and buffers.
struct SearchSet<'c> {
    strategy: Neighbors,
    sort: SortAlgo,
    n: u32,
    radius: f32,
    grid: GridSpec,
    max_nb: u32,
    search: &'c NeighborSearch,
    p: Guard<'c, Buffer>,
    b: Guard<'c, crate::primitives::neighbors::NeighborBuffers>,
}

pub fn neighbors(ctx: &Context, opts: &BenchOptions) -> Result<Vec<Row>> {
    let sw = &opts.switches;
    let combos: Vec<(Neighbors, SortAlgo)> = match sw.search.neighbors {
        Some(s) => vec![(s, sw.sorting.sort.unwrap_or(default_sort(s)))],
        None => vec![
            (Neighbors::Grid, SortAlgo::Counting),
            (Neighbors::Hash, SortAlgo::Bitonic),
            (Neighbors::Hash, SortAlgo::OddEven),
            (Neighbors::Morton, SortAlgo::OddEven),
        ],
    };
    let mut searches = Guard::new(ctx, Vec::new());
    for &(strategy, sort) in &combos {
        searches.push(NeighborSearch::new(ctx, strategy, Some(sort))?);
    }
    let mut sets = Vec::new();
    for (k, &(strategy, sort)) in combos.iter().enumerate() {
        let search = &searches[k];
        for n in counts(opts) {
            let radius = radius_for(n, 30.0);
            let grid = GridSpec::covering([0.0; 3], [1.0; 3], radius)?;
            let mut rng = rand_pcg::Pcg32::seed_from_u64(sw.common.seed);
            let pos: Vec<[f32; 4]> = (0..n)
                .map(|_| [rng.random(), rng.random(), rng.random(), 1.0])
                .collect();
            let mut p = Guard::new(ctx, ctx.storage_buffer("bench positions", n as u64 * 16)?);
            ctx.upload(&mut p, 0, &pos)?;
            // Up to 64 listed neighbours, fewer where the lists would exceed one binding.
            let max_nb = (ctx.max_storage_range() / (n as u64 * 4)).min(64) as u32;
            let b = Guard::new(ctx, search.buffers(ctx, n as u64, &grid, max_nb)?);
            sets.push(SearchSet {
                strategy,
                sort,
                n,
                radius,
                grid,
                max_nb,
                search,
                p,
                b,
            });
        }
    }
    let cases = sets
        .iter()
        .map(|s| {
            let variant = format!("{}-{}", s.strategy.as_str(), s.sort.as_str());
            let detail =
                json!({ "radius": s.radius, "grid": s.grid.dims, "max_neighbors": s.max_nb });
            Case::new(variant, s.n as u64, NEIGHBORS, detail, move |prof, cmd| {
                {
                    let mut prof = prof.open(ctx, cmd, NEIGHBORS.scope());
                    s.search
                        .record_build(ctx, cmd, &mut *prof, &s.b, &s.p, s.n, &s.grid)?;
                    s.search
                        .record_query(ctx, cmd, &mut *prof, &s.b, &s.p, s.n, &s.grid, s.radius)?;
                }
                Ok(())
            })
        })
        .collect();
    let mut rows = protocol::run(ctx, opts, cases)?;
    for (row, s) in rows.iter_mut().zip(&sets) {
        let n = s.n as usize;
        row.variant = format!("{}/{}", s.strategy.as_str(), s.sort.as_str());
        let c: Vec<u32> = ctx.readback(&s.b.counts, 0, n)?;
        let v: Vec<u32> = ctx.readback(&s.b.visited, 0, n)?;
        let total = |x: &[u32]| x.iter().map(|&a| a as u64).sum::<u64>();
        let (pairs, visited) = (total(&c), total(&v) as f64 / n as f64);
        row.extra = vec![
            (
                "mean neighbours".into(),
                format!("{:.1}", pairs as f64 / n as f64),
            ),
            ("mean candidates".into(), format!("{visited:.1}")),
            // Exact: every strategy must find the same pairs in the same points.
            (NEIGHBOUR_PAIRS.into(), pairs.to_string()),
        ];
    }
    drop(sets);
    Ok(rows)
}

/// Ratios the speed targets ask for, computed from the rows measured together.
const NEIGHBOUR_PAIRS: &str = "neighbour pairs";

/// Rows whose neighbour pairs differ from grid/counting's at the same N (same points).
fn pair_mismatches(rows: &[Row]) -> (usize, Vec<String>) {
    let pairs = |r: &Row| {
        r.extra
            .iter()
            .find(|(k, _)| k == NEIGHBOUR_PAIRS)
            .map(|(_, v)| v.clone())
    };
    let mut checked = 0;
    let mut bad = Vec::new();
    for r in rows.iter().filter(|r| r.variant != "grid/counting") {
        let grid = rows
            .iter()
            .find(|g| g.variant == "grid/counting" && g.n == r.n);
        if let (Some(g), Some(mine)) = (grid.and_then(pairs), pairs(r)) {
            checked += 1;
            if g != mine {
                bad.push(format!(
                    "WARNING: {} at {} found {mine} neighbour pairs, grid/counting {g}",
                    r.variant, r.n
                ));
            }
        }
    }
    (checked, bad)
}

/// What a bench's rows say against its targets, one line each.
pub fn notes(what: super::Bench, rows: &[Row]) -> Vec<String> {
    use super::Bench;
    match what {
        Bench::Solvers => super::solvers::notes(rows),
        Bench::Particles => super::particles::notes(rows),
        Bench::Emission => emission_notes(rows),
        Bench::Sort => sort_notes(rows),
        Bench::Neighbors => neighbors_notes(rows),
        Bench::Sph => sph_notes(rows),
        Bench::Render => render_notes(rows),
        Bench::March => super::march::notes(rows),
        Bench::Scan => scan_notes(rows),
        Bench::Inside => super::inside::notes(rows),
        Bench::Stability | Bench::Skin | Bench::Control => Vec::new(),
    }
}

/// The median ms of variant v's row whose N is nearest n (within 25%: scenes round
/// particle counts).
fn ms_near(rows: &[Row], v: &str, n: u64) -> Option<f64> {
    row_near(rows, v, n).map(|r| r.main.median)
}

/// The row of variant v whose N is nearest n, within 25%.
fn row_near<'a>(rows: &'a [Row], v: &str, n: u64) -> Option<&'a Row> {
    rows.iter()
        .filter(|r| r.variant == v && (r.n as f64 / n as f64 - 1.0).abs() <= 0.25)
        .min_by_key(|r| r.n.abs_diff(n))
}

fn emission_notes(rows: &[Row]) -> Vec<String> {
    let ms = |v: &str, n: u64| ms_near(rows, v, n);
    let mut out = Vec::new();
    if let (Some(h), Some(g)) = (ms("hash/bitonic", 64 << 10), ms("grid/counting", 64 << 10)) {
        out.push(format!(
            "the counting grid's frame is {:.2}x faster than hash + bitonic at 64K (target: 2x)",
            h / g
        ));
    }
    let per = |v: &str, n: u64| row_near(rows, v, n).map(|r| r.main.median / r.n as f64);
    for v in ["grid/counting", "hash/bitonic"] {
        if let (Some(a), Some(b)) = (per(v, 8 << 10), per(v, 64 << 10)) {
            out.push(format!(
                "{v}: cost per particle at 64K is {:.2}x that at 8K (target for the grid: within 1.5x)",
                b / a
            ));
        }
    }
    out
}

fn sort_notes(rows: &[Row]) -> Vec<String> {
    let ms = |v: &str, n: u64| ms_near(rows, v, n);
    let growth = |v: &str| match (ms(v, 8 << 10), ms(v, 64 << 10)) {
        (Some(a), Some(b)) => Some(format!(
            "{v}: {:.1}x from 8K to 64K (8x the elements)",
            b / a
        )),
        _ => None,
    };
    let mut out = Vec::new();
    if let (Some(o), Some(c)) = (ms("odd-even", 64 << 10), ms("counting", 64 << 10)) {
        out.push(format!(
            "counting sort is {:.1}x faster than odd-even merge sort at 64K (target: 20x)",
            o / c
        ));
    }
    if let (Some(b), Some(c)) = (ms("bitonic", 64 << 10), ms("counting", 64 << 10)) {
        out.push(format!(
            "counting sort is {:.1}x faster than bitonic sort at 64K",
            b / c
        ));
    }
    out.extend(
        ["counting", "odd-even", "bitonic"]
            .iter()
            .filter_map(|v| growth(v)),
    );
    if out.iter().any(|l| l.starts_with("counting:")) {
        out.push("target: counting grows at most 10x from 8K to 64K".into());
    }
    out
}

fn neighbors_notes(rows: &[Row]) -> Vec<String> {
    let ms = |v: &str, n: u64| ms_near(rows, v, n);
    let mut out = Vec::new();
    let (checked, bad) = pair_mismatches(rows);
    if checked > 0 && bad.is_empty() {
        out.push(format!(
            "every strategy found exactly grid/counting's neighbour pairs ({checked} rows checked)"
        ));
    }
    out.extend(bad);
    for v in [
        "grid/counting",
        "hash/bitonic",
        "hash/odd-even",
        "morton/odd-even",
    ] {
        if let (Some(a), Some(b)) = (ms(v, 8 << 10), ms(v, 1 << 20)) {
            out.push(format!(
                "{v}: cost per particle at 1M is {:.2}x that at 8K",
                (b / (1 << 20) as f64) / (a / (8 << 10) as f64)
            ));
        }
    }
    if let (Some(g), Some(m)) = (
        ms("grid/counting", 64 << 10),
        ms("morton/odd-even", 64 << 10),
    ) {
        out.push(format!(
            "grid/counting is {:.1}x faster than morton/odd-even at 64K",
            m / g
        ));
    }
    out
}

fn sph_notes(rows: &[Row]) -> Vec<String> {
    let ms = |v: &str, n: u64| ms_near(rows, v, n);
    let mut out = Vec::new();
    if let (Some(g), Some(m)) = (
        ms("grid/counting", 64 << 10),
        ms("morton/odd-even", 64 << 10),
    ) {
        out.push(format!(
            "grid/counting steps {:.1}x faster than morton/odd-even near 64K (target: 5x)",
            m / g
        ));
    }
    for v in ["grid/counting", "hash/bitonic", "morton/odd-even"] {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.variant == v).collect();
        if let (Some(a), Some(b)) = (mine.first(), mine.last()) {
            if a.n != b.n {
                let per = |r: &Row| r.main.median / r.n as f64;
                out.push(format!(
                    "{v}: cost per particle at {} is {:.2}x that at {} (grid target: within 2x)",
                    b.n,
                    per(b) / per(a),
                    a.n
                ));
            }
        }
    }
    out
}

fn render_notes(rows: &[Row]) -> Vec<String> {
    let mut out = Vec::new();
    for r in rows {
        let cut = r.extra.iter().find(|(k, _)| k == "pixels past loop budget");
        if let Some((_, v)) = cut.filter(|(_, v)| v != "0") {
            out.push(format!("WARNING: {}: {v} pixels' rays were cut short by llvmpipe's loop budget, so this row understates the cost", r.variant));
        }
    }
    let get = |v: &str| rows.iter().find(|r| r.variant == v);
    for sv in ["sbuffer", "sbuffer-sorted"] {
        if let (Some(s), Some(none)) = (get(sv), get("none")) {
            out.push(format!(
                "{sv}: {:.1}x the frame rate of none (target: 12x)",
                none.main.median / s.main.median
            ));
        }
        if let (Some(s), Some(a)) = (get(sv), get("abuffer")) {
            out.push(format!(
                "{sv}: {:.2}x the frame rate of abuffer (target: > 1)",
                a.main.median / s.main.median
            ));
            let mb = |r: &Row| {
                r.extra
                    .iter()
                    .find(|(k, _)| k == "list MB")
                    .and_then(|(_, v)| v.parse::<f64>().ok())
            };
            if let (Some(ms), Some(ma)) = (mb(s), mb(a)) {
                out.push(format!(
                    "{sv} memory is {:.2}x abuffer's (target: at most 0.7x)",
                    ms / ma
                ));
            }
        }
    }
    out
}

fn scan_notes(rows: &[Row]) -> Vec<String> {
    let mut out = Vec::new();
    for r in rows.iter().filter(|r| r.n == 16 << 20) {
        if let Some((_, v)) = r.extra.iter().find(|(k, _)| k == "scan/copy bandwidth") {
            out.push(format!("scan of 16M u32 reaches {v} of the copy bandwidth measured in the same frames (target: 30% lavapipe, 50% GPU)"));
        }
    }
    out
}
