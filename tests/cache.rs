//! The caches a process leaves for the next (gpu/cache.rs): kept SPIR-V and the Vulkan
//! pipeline cache are used by the next run of the same binary, and a stale or broken one
//! is ignored with one line, never trusted.
mod common;
use common::text;
use std::path::Path;
use std::process::Command;

fn scan(cache: &Path, out: &Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_fluidform"))
        .args([
            "bench",
            "scan",
            "--particles",
            "1000",
            "--frames",
            "5",
            "--warmup",
            "1",
        ])
        .args(["--validation", "--quiet", "--out", out.to_str().unwrap()])
        .env("FLUIDFORM_CACHE_DIR", cache)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    text(&o)
}

fn pipeline_file(cache: &Path) -> std::path::PathBuf {
    let files: Vec<_> = std::fs::read_dir(cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with("pipelines-")
        })
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    files[0].clone()
}

#[test]
fn a_stale_cache_is_ignored_with_one_line_and_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let (cache, out) = (dir.path().join("cache"), dir.path().join("out"));
    let first = scan(&cache, &out);
    assert!(!first.contains("ignoring"), "{first}");
    let spirv = std::fs::read_dir(cache.join("spirv")).unwrap().count();
    assert!(spirv > 0, "no SPIR-V kept");
    let file = pipeline_file(&cache);
    let good = std::fs::read(&file).unwrap();
    // A second run trusts its own files and adds none.
    let again = scan(&cache, &out);
    assert!(!again.contains("ignoring"), "{again}");
    assert_eq!(
        std::fs::read_dir(cache.join("spirv")).unwrap().count(),
        spirv
    );
    // Another binary's, another driver's, and no cache at all: one line each, then the
    // file is this binary's again.
    for (range, byte, why) in [
        (8..16, 0xee, "made by another fluidform binary"),
        (16..20, 0xee, "made by another driver version"),
        (0..8, b'x', "not a fluidform pipeline cache"),
    ] {
        let mut stale = good.clone();
        stale[range].fill(byte);
        std::fs::write(&file, &stale).unwrap();
        let log = scan(&cache, &out);
        let lines: Vec<&str> = log
            .lines()
            .filter(|l| l.contains("ignoring the pipeline cache"))
            .collect();
        assert_eq!(lines.len(), 1, "{log}");
        assert!(lines[0].ends_with(why), "{}", lines[0]);
        assert_eq!(
            &std::fs::read(&file).unwrap()[..20],
            &good[..20],
            "not replaced"
        );
    }
    // Broken SPIR-V is recompiled, not used: the run still passes its own checks.
    for e in std::fs::read_dir(cache.join("spirv")).unwrap() {
        std::fs::write(e.unwrap().path(), [0u8; 64]).unwrap();
    }
    let log = scan(&cache, &out);
    assert!(log.contains("scan"), "{log}");
}

/// The context's keyed pipelines (gpu/pipelines.rs): one key is one Vulkan pipeline, shared
/// by every holder and destroyed with its last; another workgroup size is another key.
#[test]
fn one_key_is_one_pipeline_until_its_last_holder_goes() {
    use fluidform::primitives::bounds::{BoundsBuffers, BoundsPass, BOUNDS};
    let ctx = common::ctx();
    let mut a = BOUNDS.pipeline(&ctx, &(), 256, &[8]).unwrap();
    let mut other = BOUNDS.pipeline(&ctx, &(), 128, &[8]).unwrap();
    let mut pass = BoundsPass::new(&ctx).unwrap(); // 256 wide, 8 per invocation: a's key
    assert_ne!(
        a.pipeline, other.pipeline,
        "another workgroup size, another pipeline"
    );
    assert_eq!(ctx.live_objects().get("pipeline"), Some(&2));
    assert_eq!(ctx.pipelines.len(), 2);
    a.destroy(&ctx);
    assert_eq!(ctx.pipelines.len(), 2, "the pass still holds a's pipeline");
    // The pass's pipeline still runs: the box of known positions.
    let pos: Vec<[f32; 4]> = (0..5000)
        .map(|i| {
            let t = i as f32 * 0.01;
            [t.sin() * 2.0, t.cos() - 3.0, t * 0.1, 1.0]
        })
        .collect();
    let mut buf = ctx
        .storage_buffer("positions", pos.len() as u64 * 16)
        .unwrap();
    ctx.upload(&mut buf, 0, &pos).unwrap();
    let mut b = BoundsBuffers::new(&ctx, pos.len() as u64).unwrap();
    ctx.one_shot(|cmd| pass.record(&ctx, cmd, &buf, pos.len() as u64, &b))
        .unwrap()
        .unwrap();
    let got: Vec<[f32; 4]> = ctx.read_all(&b.result).unwrap();
    for k in 0..3 {
        let lo = pos.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min);
        let hi = pos.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max);
        assert_eq!((got[0][k], got[1][k]), (lo, hi), "axis {k}");
    }
    pass.destroy(&ctx);
    other.destroy(&ctx);
    assert!(ctx.pipelines.is_empty());
    b.destroy(&ctx);
    ctx.destroy_buffer(&mut buf);
    common::finish(&ctx);
}
