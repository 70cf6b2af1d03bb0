//! GPU primitives against their CPU references, for awkward sizes and inputs.
mod common;
use fluidform::gpu::Context;
use fluidform::primitives::bounds::{BoundsBuffers, BoundsPass};
use fluidform::primitives::counting::{CountingBuffers, CountingSort};
use fluidform::primitives::cpu;
use fluidform::primitives::morton::{morton_axis, morton_code, MortonPass};
use fluidform::primitives::scan::{ScanKind, ScanPass, ScanVariant};
use fluidform::primitives::sort::{Network, NetworkSort};
use rand::{Rng, SeedableRng};

const SIZES: &[usize] = &[0, 1, 2, 3, 31, 32, 33, 1000, 4095, 4097, 65536, 1_000_003];

#[derive(Clone, Copy, Debug)]
enum Input {
    AllEqual,
    Sorted,
    Reversed,
    Random,
}
const INPUTS: [Input; 4] = [
    Input::AllEqual,
    Input::Sorted,
    Input::Reversed,
    Input::Random,
];

/// Keys of one input kind, below `range` (u32::MAX: the full range).
fn keys(kind: Input, n: usize, range: u32, seed: u64) -> Vec<u32> {
    let span = |i: usize| ((i as u64 * range as u64) / n.max(1) as u64) as u32;
    match kind {
        Input::AllEqual => vec![range / 2; n],
        Input::Sorted => (0..n).map(span).collect(),
        Input::Reversed => (0..n).rev().map(span).collect(),
        Input::Random => {
            let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
            (0..n).map(|_| rng.random_range(0..range)).collect()
        }
    }
}

fn buf(ctx: &Context, name: &str, data: &[u32]) -> fluidform::gpu::Buffer {
    let mut b = ctx
        .storage_buffer(name, (data.len().max(1) * 4) as u64)
        .unwrap();
    ctx.upload(&mut b, 0, data).unwrap();
    b
}

fn check_scan(ctx: &Context, pass: &ScanPass, sizes: &[usize]) {
    let max = *sizes.iter().max().unwrap() as u64;
    let mut scratch = pass.scratch(ctx, max).unwrap();
    for &n in sizes {
        for kind in [ScanKind::Exclusive, ScanKind::Inclusive] {
            // Random values (some large, so sums wrap) and all-ones.
            for (what, data) in [
                (
                    "random",
                    common::random_u32(n, n as u64)
                        .iter()
                        .map(|v| v >> 4)
                        .collect::<Vec<_>>(),
                ),
                ("ones", vec![1u32; n]),
            ] {
                let input = buf(ctx, "scan in", &data);
                let output = ctx
                    .storage_buffer("scan out", (n.max(1) * 4) as u64)
                    .unwrap();
                ctx.one_shot(|cmd| {
                    pass.record(ctx, cmd, &input, &output, n as u64, kind, &scratch)
                })
                .unwrap()
                .unwrap();
                let got: Vec<u32> = ctx.readback(&output, 0, n).unwrap();
                let want = cpu::scan(&data, kind == ScanKind::Inclusive);
                if let Some(i) = got.iter().zip(&want).position(|(a, b)| a != b) {
                    panic!(
                        "{kind:?} scan of {n} {what} (subgroups: {}): [{i}] = {} != {}",
                        pass.uses_subgroups, got[i], want[i]
                    );
                }
                // In place.
                let mut inplace = input;
                ctx.one_shot(|cmd| {
                    pass.record(ctx, cmd, &inplace, &inplace, n as u64, kind, &scratch)
                })
                .unwrap()
                .unwrap();
                assert_eq!(
                    ctx.readback::<u32>(&inplace, 0, n).unwrap(),
                    want,
                    "in-place {kind:?} n = {n}"
                );
                let mut output = output;
                ctx.destroy_buffer(&mut inplace);
                ctx.destroy_buffer(&mut output);
            }
        }
    }
    scratch.destroy(ctx);
}

#[test]
fn scan_matches_cpu_subgroup_and_shared() {
    let ctx = common::ctx();
    let mut variants = vec![ScanVariant::SharedMemory];
    // llvmpipe has subgroup arithmetic: there the subgroup variant must run.
    assert!(ctx.info.subgroup_arithmetic || !ctx.info.name.contains("llvmpipe"));
    if ctx.info.subgroup_arithmetic {
        variants.push(ScanVariant::Subgroup);
    } else {
        eprintln!(
            "{}: no subgroup arithmetic, subgroup scan not run",
            ctx.info.name
        );
    }
    for v in variants {
        let mut pass = ScanPass::new(&ctx, v).unwrap();
        check_scan(
            &ctx,
            &pass,
            &[
                0, 1, 2, 3, 31, 32, 33, 63, 64, 65, 1000, 4095, 4096, 4097, 65536, 262_145,
                1_000_003, 4_194_305,
            ],
        );
        pass.destroy(&ctx);
    }
    common::finish(&ctx);
}

#[test]
fn scan_of_2_pow_26_plus_3_crosses_binding_segments() {
    // 2^26 + 3 u32 is 256 MiB: more than lavapipe's 128 MiB maxStorageBufferRange.
    let ctx = common::ctx();
    let n = (1usize << 26) + 3;
    assert!(
        n as u64 * 4 > ctx.max_storage_range() || !ctx.info.name.contains("llvmpipe"),
        "the array must exceed one binding for this test to cross a segment"
    );
    let mut pass = ScanPass::new(&ctx, ScanVariant::Auto).unwrap();
    let mut scratch = pass.scratch(&ctx, n as u64).unwrap();
    let data: Vec<u32> = (0..n as u32)
        .map(|i| i.wrapping_mul(2654435761) >> 28)
        .collect();
    let mut input = buf(&ctx, "scan in", &data);
    ctx.one_shot(|cmd| {
        pass.record(
            &ctx,
            cmd,
            &input,
            &input,
            n as u64,
            ScanKind::Inclusive,
            &scratch,
        )
    })
    .unwrap()
    .unwrap();
    let got: Vec<u32> = ctx.read_all(&input).unwrap();
    let want = cpu::scan(&data, true);
    let bad = got.iter().zip(&want).position(|(a, b)| a != b);
    assert!(bad.is_none(), "first mismatch at {bad:?}");
    ctx.destroy_buffer(&mut input);
    scratch.destroy(&ctx);
    pass.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn bounds_and_morton_match_cpu() {
    let ctx = common::ctx();
    let mut bounds = BoundsPass::new(&ctx).unwrap();
    let mut morton = MortonPass::new(&ctx).unwrap();
    for &n in &[1usize, 2, 33, 4097, 65536, 1_000_003] {
        let mut rng = rand_pcg::Pcg32::seed_from_u64(n as u64);
        let pos: Vec<[f32; 4]> = (0..n)
            .map(|_| {
                [
                    rng.random_range(-3.0..2.0),
                    rng.random_range(0.5..0.7),
                    rng.random_range(-100.0..100.0),
                    1.0,
                ]
            })
            .collect();
        let mut bb = BoundsBuffers::new(&ctx, n as u64).unwrap();
        let mut p = ctx.storage_buffer("pos", (n * 16) as u64).unwrap();
        ctx.upload(&mut p, 0, &pos).unwrap();
        let mut keys = ctx.storage_buffer("keys", (n * 4) as u64).unwrap();
        let mut vals = ctx.storage_buffer("vals", (n * 4) as u64).unwrap();
        ctx.one_shot(|cmd| {
            bounds.record(&ctx, cmd, &p, n as u64, &bb).unwrap();
            ctx.compute_barrier(cmd);
            morton.record(&ctx, cmd, &p, &bb.result, &keys, &vals, n as u32);
        })
        .unwrap();
        let b: Vec<[f32; 4]> = ctx.read_all(&bb.result).unwrap();
        let (lo, hi) = cpu::bounds(&pos);
        assert_eq!(&b[0][..3], &lo[..], "min, n = {n}");
        assert_eq!(&b[1][..3], &hi[..], "max, n = {n}");
        let codes: Vec<u32> = ctx.read_all(&keys).unwrap();
        let idx: Vec<u32> = ctx.read_all(&vals).unwrap();
        for i in 0..n {
            assert_eq!(idx[i], i as u32);
            // Exact, except where a coordinate lies within 1e-3 cells of a lattice plane
            // (the GPU's division may round the other way there).
            let t: Vec<f64> = (0..3)
                .map(|k| morton_axis(pos[i][k], lo[k], hi[k]))
                .collect();
            let ambiguous = t
                .iter()
                .any(|v| (v - v.round()).abs() < 1e-3 && v.round() > 0.0 && v.round() < 1024.0);
            let want = morton_code([t[0] as u32, t[1] as u32, t[2] as u32]);
            assert!(
                ambiguous || codes[i] == want,
                "n = {n}, point {i}: {:#x} vs {want:#x}",
                codes[i]
            );
        }
        for b in [&mut p, &mut keys, &mut vals] {
            ctx.destroy_buffer(b);
        }
        bb.destroy(&ctx);
    }
    // Empty input gives an empty (inverted) box, not garbage.
    let mut bb = BoundsBuffers::new(&ctx, 0).unwrap();
    let mut p = ctx.storage_buffer("pos", 16).unwrap();
    ctx.one_shot(|cmd| bounds.record(&ctx, cmd, &p, 0, &bb).unwrap())
        .unwrap();
    let b: Vec<[f32; 4]> = ctx.read_all(&bb.result).unwrap();
    assert!(b[0][0] > b[1][0]);
    ctx.destroy_buffer(&mut p);
    bb.destroy(&ctx);
    bounds.destroy(&ctx);
    morton.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn morton_code_interleaves_bits() {
    assert_eq!(morton_code([1, 0, 0]), 0b100);
    assert_eq!(morton_code([0, 1, 0]), 0b010);
    assert_eq!(morton_code([0, 0, 1]), 0b001);
    assert_eq!(morton_code([1023, 1023, 1023]), (1 << 30) - 1);
    assert_eq!(morton_code([2, 0, 0]), 0b100_000);
}

fn check_network(network: Network) {
    let ctx = common::ctx();
    let mut sort = NetworkSort::new(&ctx, network).unwrap();
    for &n in SIZES {
        for kind in INPUTS {
            let k = keys(kind, n, u32::MAX, n as u64 ^ 0x5eed);
            let v: Vec<u32> = (0..n as u32).collect();
            let mut kb = buf(&ctx, "keys", &k);
            let mut vb = buf(&ctx, "vals", &v);
            ctx.one_shot(|cmd| sort.record(&ctx, cmd, &kb, &vb, n as u64).unwrap())
                .unwrap();
            let gk: Vec<u32> = ctx.readback(&kb, 0, n).unwrap();
            let gv: Vec<u32> = ctx.readback(&vb, 0, n).unwrap();
            if let Err(e) = cpu::check_sorted_pairs(&k, &v, &gk, &gv) {
                panic!("{network:?} n = {n} {kind:?}: {e}");
            }
            ctx.destroy_buffer(&mut kb);
            ctx.destroy_buffer(&mut vb);
        }
    }
    sort.destroy(&ctx);
    common::finish(&ctx);
}

#[test]
fn odd_even_merge_sort_matches_cpu() {
    check_network(Network::OddEven);
}

#[test]
fn bitonic_sort_matches_cpu() {
    check_network(Network::Bitonic);
}

#[test]
fn counting_sort_matches_cpu() {
    let ctx = common::ctx();
    let mut scan = ScanPass::new(&ctx, ScanVariant::Auto).unwrap();
    let mut sort = CountingSort::new(&ctx).unwrap();
    for &n in SIZES {
        for kind in INPUTS {
            // Cell keys: about four elements per cell, as in a particle grid.
            let cells = (n as u32 / 4).max(1);
            let k = keys(kind, n, cells, n as u64 ^ 0xce11);
            let v: Vec<u32> = (0..n as u32).collect();
            let mut bufs = CountingBuffers::new(&ctx, &scan, n as u64, cells).unwrap();
            let mut kb = buf(&ctx, "keys", &k);
            let mut vb = buf(&ctx, "vals", &v);
            let mut sk = ctx
                .storage_buffer("sorted keys", (n.max(1) * 4) as u64)
                .unwrap();
            let mut sv = ctx
                .storage_buffer("sorted vals", (n.max(1) * 4) as u64)
                .unwrap();
            ctx.one_shot(|cmd| sort.record(&ctx, cmd, &scan, &bufs, &kb, &vb, &sk, &sv, n as u64))
                .unwrap()
                .unwrap();
            let gk: Vec<u32> = ctx.readback(&sk, 0, n).unwrap();
            let gv: Vec<u32> = ctx.readback(&sv, 0, n).unwrap();
            if let Err(e) = cpu::check_sorted_pairs(&k, &v, &gk, &gv) {
                panic!("counting n = {n} {kind:?}: {e}");
            }
            // Cell starts: the exclusive scan of the per-cell counts.
            let counts: Vec<u32> = ctx.readback(&bufs.counts, 0, cells as usize + 1).unwrap();
            let starts: Vec<u32> = ctx.readback(&bufs.starts, 0, cells as usize).unwrap();
            let mut want = vec![0u32; cells as usize];
            for &key in &k {
                want[key as usize] += 1;
            }
            assert_eq!(&counts[..cells as usize], &want[..], "counts n = {n}");
            assert_eq!(counts[cells as usize], 0, "no out-of-range keys");
            assert_eq!(starts, cpu::scan(&want, false), "starts n = {n}");
            for b in [&mut kb, &mut vb, &mut sk, &mut sv] {
                ctx.destroy_buffer(b);
            }
            bufs.destroy(&ctx);
        }
    }
    sort.destroy(&ctx);
    scan.destroy(&ctx);
    common::finish(&ctx);
}
