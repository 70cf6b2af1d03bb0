//! Every neighbour strategy returns exactly the brute-force neighbour set.
mod common;
use fluidform::gpu::{Context, Labels};
use fluidform::kinds::{Neighbors, SortAlgo};
use fluidform::primitives::cpu;
use fluidform::primitives::neighbors::{GridSpec, NeighborSearch};
use rand::{Rng, SeedableRng};

const MAX_NB: u32 = 96;

/// Random points in the unit cube plus a dense clump, duplicates and a few far outside
/// the grid (clamped into border cells).
fn points(n: usize, seed: u64) -> Vec<[f32; 4]> {
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut v: Vec<[f32; 4]> = (0..n)
        .map(|_| [rng.random(), rng.random(), rng.random(), 1.0])
        .collect();
    for p in v.iter_mut().take(n / 50) {
        *p = [
            0.5 + rng.random::<f32>() * 0.02,
            0.5,
            0.5 + rng.random::<f32>() * 0.02,
            1.0,
        ];
    }
    if n > 10 {
        v[n - 1] = v[n - 2];
        v[n - 3] = [-3.0, 0.5, 0.5, 1.0];
        v[n - 4] = [-3.01, 0.5, 0.5, 1.0];
        v[n - 5] = [0.2, 7.0, 0.9, 1.0];
    }
    v
}

/// A point set with its brute-force neighbours and which particles have a neighbour
/// within 1e-6 of the radius (f32 may decide those either way).
struct Case {
    pos: Vec<[f32; 4]>,
    radius: f32,
    want: Vec<Vec<u32>>,
    ambiguous: Vec<bool>,
}

fn case(n: usize, radius: f32) -> Case {
    let pos = points(n, n as u64 + 11);
    let want = cpu::brute_neighbors(&pos, radius);
    let r2 = (radius as f64).powi(2);
    let ambiguous = (0..n)
        .map(|i| (0..n).any(|j| j != i && (cpu::dist2(&pos[i], &pos[j]) - r2).abs() < 1e-6))
        .collect();
    Case {
        pos,
        radius,
        want,
        ambiguous,
    }
}

fn check(ctx: &Context, strategy: Neighbors, sort: SortAlgo, c: &Case) {
    let (pos, radius, n) = (&c.pos, c.radius, c.pos.len());
    let grid = GridSpec::covering([0.0; 3], [1.0; 3], radius).unwrap();
    let mut search = NeighborSearch::new(ctx, strategy, Some(sort)).unwrap();
    let mut b = search.buffers(ctx, n as u64, &grid, MAX_NB).unwrap();
    let mut p = ctx.storage_buffer("positions", (n * 16) as u64).unwrap();
    ctx.upload(&mut p, 0, pos).unwrap();
    ctx.one_shot(|cmd| {
        search.record_build(ctx, cmd, &mut Labels, &b, &p, n as u32, &grid)?;
        search.record_query(ctx, cmd, &mut Labels, &b, &p, n as u32, &grid, radius)
    })
    .unwrap()
    .unwrap();
    let perm: Vec<u32> = ctx.readback(&b.perm, 0, n).unwrap();
    let counts: Vec<u32> = ctx.readback(&b.counts, 0, n).unwrap();
    let list: Vec<u32> = ctx.readback(&b.list, 0, n * MAX_NB as usize).unwrap();
    let sorted_pos: Vec<[f32; 4]> = ctx.readback(&b.sorted_pos, 0, n).unwrap();
    let want = &c.want;
    let mut seen = vec![false; n];
    let mut compared = 0;
    for s in 0..n {
        let i = perm[s] as usize;
        assert!(
            !seen[i],
            "{strategy:?}/{sort:?}: {i} twice in the permutation"
        );
        seen[i] = true;
        assert_eq!(sorted_pos[s], pos[i], "reordered position of {i}");
        let count = counts[s] as usize;
        if !c.ambiguous[i] {
            assert_eq!(
                count,
                want[i].len(),
                "{strategy:?}/{sort:?} n = {n}: count of particle {i}"
            );
        }
        if count <= MAX_NB as usize && !c.ambiguous[i] {
            let mut got: Vec<u32> = list[s * MAX_NB as usize..][..count]
                .iter()
                .map(|&j| perm[j as usize])
                .collect();
            got.sort_unstable();
            assert_eq!(
                got, want[i],
                "{strategy:?}/{sort:?} n = {n}: neighbours of {i}"
            );
            compared += 1;
        }
    }
    assert!(
        compared > n * 9 / 10,
        "only {compared} of {n} lists compared"
    );
    ctx.destroy_buffer(&mut p);
    b.destroy(ctx);
    search.destroy(ctx);
}

#[test]
fn every_strategy_matches_brute_force() {
    let ctx = common::ctx();
    let combos = [
        (Neighbors::Grid, SortAlgo::Counting),
        (Neighbors::Grid, SortAlgo::Bitonic),
        (Neighbors::Hash, SortAlgo::Bitonic),
        (Neighbors::Hash, SortAlgo::OddEven),
        (Neighbors::Hash, SortAlgo::Counting),
        (Neighbors::Morton, SortAlgo::OddEven),
        (Neighbors::Morton, SortAlgo::Bitonic),
    ];
    let cases: Vec<Case> = [
        (1usize, 0.1f32),
        (2, 0.5),
        (33, 0.3),
        (1000, 0.12),
        (4097, 0.08),
        (20000, 0.05),
    ]
    .into_iter()
    .map(|(n, r)| case(n, r))
    .collect();
    for (strategy, sort) in combos {
        for c in &cases {
            check(&ctx, strategy, sort, c);
        }
    }
    common::finish(&ctx);
}

#[test]
fn morton_with_counting_sort_is_rejected() {
    let ctx = common::ctx();
    let e = NeighborSearch::new(&ctx, Neighbors::Morton, Some(SortAlgo::Counting))
        .err()
        .unwrap();
    assert!(e.to_string().contains("--sort odd-even or bitonic"), "{e}");
    assert!(
        GridSpec::covering([0.0; 3], [1.0; 3], 1e-4).is_err(),
        "a grid of 10^12 cells is refused"
    );
    common::finish(&ctx);
}

#[test]
fn morton_equals_grid_per_particle_beyond_the_loop_budget() {
    // Beyond the brute-force sizes: the same count for every particle as the grid (which
    // matches brute force above). At 131072 points some Morton ranges exceed 65535
    // candidates, more than llvmpipe's per-invocation loop budget if walked one by one.
    let ctx = common::ctx();
    let n = 131_072usize;
    let radius = fluidform::bench::primitives::radius_for(n as u32, 30.0);
    let grid = GridSpec::covering([0.0; 3], [1.0; 3], radius).unwrap();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(1);
    let pos: Vec<[f32; 4]> = (0..n)
        .map(|_| [rng.random(), rng.random(), rng.random(), 1.0])
        .collect();
    let mut p = ctx.storage_buffer("positions", (n * 16) as u64).unwrap();
    ctx.upload(&mut p, 0, &pos).unwrap();
    let mut by_strategy = Vec::new();
    for (strategy, sort) in [
        (Neighbors::Grid, SortAlgo::Counting),
        (Neighbors::Morton, SortAlgo::Bitonic),
    ] {
        let mut search = NeighborSearch::new(&ctx, strategy, Some(sort)).unwrap();
        let mut b = search.buffers(&ctx, n as u64, &grid, 1).unwrap();
        ctx.one_shot(|cmd| {
            search.record_build(&ctx, cmd, &mut Labels, &b, &p, n as u32, &grid)?;
            search.record_query(&ctx, cmd, &mut Labels, &b, &p, n as u32, &grid, radius)
        })
        .unwrap()
        .unwrap();
        let perm: Vec<u32> = ctx.readback(&b.perm, 0, n).unwrap();
        let counts: Vec<u32> = ctx.readback(&b.counts, 0, n).unwrap();
        let visited: Vec<u32> = ctx.readback(&b.visited, 0, n).unwrap();
        if strategy == Neighbors::Morton {
            let longest = visited.iter().max().copied().unwrap_or(0);
            assert!(
                longest > 65_535,
                "longest range {longest}: none beyond the budget, or cut short"
            );
        }
        let mut by_id = vec![0u32; n];
        for s in 0..n {
            by_id[perm[s] as usize] = counts[s];
        }
        by_strategy.push(by_id);
        b.destroy(&ctx);
        search.destroy(&ctx);
    }
    let differ = (0..n)
        .filter(|&i| by_strategy[0][i] != by_strategy[1][i])
        .count();
    assert_eq!(
        differ, 0,
        "{differ} particles have other neighbour counts with morton than with grid"
    );
    ctx.destroy_buffer(&mut p);
    common::finish(&ctx);
}
