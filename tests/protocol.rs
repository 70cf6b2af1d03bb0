//! The measurement protocol (bench/protocol.rs): the bootstrap against a known
//! distribution, rounds interleaved in a seeded shuffled order, a perturbation flagged in
//! exactly the rows it slowed, and the Chrome trace (nested scopes, with and without
//! calibrated timestamps).
mod common;
use common::{fluidform, text};
use fluidform::bench::interval::{bootstrap_median, median, Interval};
use rand::SeedableRng;
use rand_distr_free::normal;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// Standard normal samples by Box-Muller (no extra crate for one distribution).
mod rand_distr_free {
    use rand::Rng;
    pub fn normal(rng: &mut impl Rng, mean: f64, sd: f64) -> f64 {
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        mean + sd * (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

#[test]
fn bootstrap_interval_of_a_known_distribution() {
    // The median of n normal samples has standard error sqrt(pi/2) sd / sqrt(n), so its
    // 95% interval is about +-1.96 of that around the true median.
    let (n, mean, sd) = (1001, 10.0, 1.0);
    let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
    let v: Vec<f64> = (0..n).map(|_| normal(&mut rng, mean, sd)).collect();
    let (lo, hi) = bootstrap_median(&v, 2000, 11).unwrap();
    let m = median(&v).unwrap();
    assert!(lo < m && m < hi, "[{lo}, {hi}] around {m}");
    assert!(
        lo < mean && mean < hi,
        "[{lo}, {hi}] misses the true median {mean}"
    );
    let expected = 2.0 * 1.96 * (std::f64::consts::PI / 2.0).sqrt() * sd / (n as f64).sqrt();
    let width = hi - lo;
    assert!(
        (width / expected - 1.0).abs() < 0.3,
        "width {width:.4} against the theory's {expected:.4}"
    );
    // Coverage over many samples: about 95% of intervals hold the true median.
    let mut held = 0;
    for k in 0..200 {
        let v: Vec<f64> = (0..101).map(|_| normal(&mut rng, mean, sd)).collect();
        let (lo, hi) = bootstrap_median(&v, 500, k).unwrap();
        held += (lo <= mean && mean <= hi) as u32;
    }
    assert!(
        (180..=198).contains(&held),
        "{held} of 200 intervals held the median"
    );
    // Seeded: the same seed, the same interval; rounds resampled, not frames.
    assert_eq!(
        bootstrap_median(&v, 2000, 11),
        bootstrap_median(&v, 2000, 11)
    );
    let rounds = vec![vec![1.0, 1.1, 0.9], vec![2.0, 2.1], vec![1.5]];
    let iv = Interval::of_rounds(&rounds, 3).unwrap();
    assert_eq!(iv.median, 1.5);
    assert!(iv.lo >= 1.0 && iv.hi <= 2.05 && iv.lo <= iv.median && iv.median <= iv.hi);
}

fn rows(p: &Path) -> Vec<HashMap<String, String>> {
    let mut r = csv::Reader::from_path(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let head: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    r.records()
        .map(|rec| {
            head.iter()
                .cloned()
                .zip(rec.unwrap().iter().map(String::from))
                .collect()
        })
        .collect()
}

/// The tests that launch benchmarks take turns: lavapipe is the CPU, so a sibling test's
/// benchmark would load the device the perturbation test expects to be steady.
static DEVICE: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn device() -> std::sync::MutexGuard<'static, ()> {
    DEVICE.lock().unwrap_or_else(|e| e.into_inner())
}

fn bench_sort(out: &Path, frames: &str, env: &[(&str, &str)], extra: &[&str]) -> String {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_fluidform"));
    cmd.args([
        "bench",
        "sort",
        "--particles",
        "2048",
        "--frames",
        frames,
        "--warmup",
        "1",
    ])
    .args(["--validation", "--quiet", "--out", out.to_str().unwrap()])
    .args(extra);
    for (k, v) in env {
        cmd.env(k, v);
    }
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    text(&o)
}

#[test]
fn rounds_are_interleaved_in_a_seeded_shuffled_order() {
    let _device = device();
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    bench_sort(&a, "5", &[], &[]);
    bench_sort(&b, "5", &[], &[]);
    let ra = rows(&a.join("rounds.csv"));
    let order = |rs: &[HashMap<String, String>]| -> Vec<Vec<(String, String)>> {
        (0..5)
            .map(|r| {
                let mut v: Vec<(String, String)> = rs
                    .iter()
                    .filter(|x| x["round"] == r.to_string())
                    .map(|x| (x["position"].clone(), x["variant"].clone()))
                    .collect();
                v.sort();
                v
            })
            .collect()
    };
    let oa = order(&ra);
    for (r, o) in oa.iter().enumerate() {
        // Every case once in every round, at positions 0, 1, 2.
        let variants: HashSet<&str> = o.iter().map(|(_, v)| v.as_str()).collect();
        assert_eq!(
            variants,
            HashSet::from(["odd-even", "bitonic", "counting"]),
            "round {r}"
        );
        let pos: Vec<&str> = o.iter().map(|(p, _)| p.as_str()).collect();
        assert_eq!(pos, ["0", "1", "2"], "round {r}");
    }
    let distinct: HashSet<Vec<&str>> = oa
        .iter()
        .map(|o| o.iter().map(|(_, v)| v.as_str()).collect())
        .collect();
    assert!(
        distinct.len() > 1,
        "every round ran in the same order: {oa:?}"
    );
    // The order is the seed's: a second run has the same one.
    assert_eq!(oa, order(&rows(&b.join("rounds.csv"))));
    // Each case's summary carries its rounds and interval; the table its interval.
    let s: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(a.join("runs/counting-2048/summary.json")).unwrap(),
    )
    .unwrap();
    let iv = &s["stats"]["interval"];
    assert!(iv["lo"].as_f64().unwrap() <= iv["median"].as_f64().unwrap());
    assert!(iv["median"].as_f64().unwrap() <= iv["hi"].as_f64().unwrap());
    assert_eq!(s["stats"]["rounds"].as_array().unwrap().len(), 5);
    let protocol: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("protocol.json")).unwrap()).unwrap();
    let prov = &protocol["provenance"];
    for k in ["commit", "rustc", "date"] {
        assert!(!prov[k].as_str().unwrap().is_empty(), "provenance {k}");
    }
    assert!(std::fs::read_to_string(a.join("sweep.md"))
        .unwrap()
        .contains("Protocol:"));
}

#[test]
fn a_perturbation_is_flagged_in_every_perturbed_row_and_no_other() {
    let _device = device();
    let dir = tempfile::tempdir().unwrap();
    // Three frames a round, so one noisy frame does not move a round's median. The
    // perturbation runs the sentinel ten times (+900%). lavapipe's sentinel alone was seen
    // to switch between two speeds 1.9x apart within one run, so a perturbed round in the
    // fast one still measured +400% against a median in the slow one, and an unperturbed
    // round in the slow one +93% against the fast; a 200% drift lies between the two.
    let hit = ["odd-even-2048@1", "counting-2048@3"];
    let log = bench_sort(
        dir.path(),
        "15",
        &[("FLUIDFORM_PERTURB", &hit.join(","))],
        &["--drift", "200"],
    );
    let flagged: HashSet<String> = rows(&dir.path().join("sweep.csv"))
        .into_iter()
        .filter(|r| r["flagged"] == "true")
        .map(|r| r["variant"].clone())
        .collect();
    assert_eq!(
        flagged,
        HashSet::from(["odd-even".into(), "counting".into()]),
        "{log}"
    );
    // The perturbed rounds were rerun and stayed off; the reason names the sentinel.
    let rs = rows(&dir.path().join("rounds.csv"));
    for (v, r) in [("odd-even", "1"), ("counting", "3")] {
        let row = rs
            .iter()
            .find(|x| x["variant"] == v && x["round"] == r)
            .unwrap();
        assert_eq!(row["rerun"], "true", "{row:?}");
        assert!(row["off"].starts_with("sentinel +"), "{row:?}");
    }
}

/// Every scope lies inside the scope it was opened in (`args.parent`, an index among the
/// frame's passes; none: the frame), and every frame's scopes inside the frame.
fn check_nesting(trace: &serde_json::Value) -> usize {
    let ev = trace["traceEvents"].as_array().unwrap();
    let mut frames: HashMap<(String, u64), (f64, f64)> = HashMap::new();
    // (case, frame, index) -> (start, end, parent index, key)
    type Span = (f64, f64, Option<u64>, String);
    let mut passes: HashMap<(String, u64, u64), Span> = HashMap::new();
    for e in ev.iter().filter(|e| e["ph"] == "X" && e["cat"] == "gpu") {
        let a = &e["args"];
        let id = (
            a["case"].as_str().unwrap().to_string(),
            a["frame"].as_u64().unwrap(),
        );
        let (ts, dur) = (e["ts"].as_f64().unwrap(), e["dur"].as_f64().unwrap());
        assert!(dur >= 0.0, "{e}");
        match a["key"].as_str().unwrap() {
            "frame" => assert!(frames.insert(id, (ts, ts + dur)).is_none(), "{e}"),
            key => {
                let k = a["index"].as_u64().unwrap();
                let v = (ts, ts + dur, a["parent"].as_u64(), key.to_string());
                assert!(passes.insert((id.0, id.1, k), v).is_none(), "{e}");
            }
        }
    }
    let mut checked = 0;
    for ((case, frame, _), (b, e, parent, key)) in &passes {
        let (pb, pe) = match parent {
            Some(p) => {
                let o = &passes[&(case.clone(), *frame, *p)];
                (o.0, o.1)
            }
            None => frames[&(case.clone(), *frame)],
        };
        // Timestamps are µs with ns resolution: allow a nanosecond of rounding.
        assert!(
            *b >= pb - 1e-3 && *e <= pe + 1e-3,
            "{key} [{b}, {e}] outside [{pb}, {pe}]"
        );
        checked += 1;
    }
    checked
}

#[test]
fn trace_nests_every_scope_with_and_without_calibrated_timestamps() {
    let _device = device();
    let dir = tempfile::tempdir().unwrap();
    let cal = dir.path().join("cal.json");
    bench_sort(
        &dir.path().join("a"),
        "5",
        &[],
        &["--trace", cal.to_str().unwrap()],
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&cal).unwrap()).unwrap();
    // 3 cases x 5 rounds: frames, each with its sentinel, restore and sort inside.
    assert!(check_nesting(&t) >= 15 * 3, "too few nested scopes");
    let ev = t["traceEvents"].as_array().unwrap();
    let cpu = ev.iter().filter(|e| e["cat"] == "cpu").count();
    // lavapipe has VK_EXT_calibrated_timestamps: a CPU track, GPU frames after their
    // recording began.
    assert_eq!(cpu, 15, "one CPU span per frame");
    assert!(t["otherData"]["clock"]
        .as_str()
        .unwrap()
        .starts_with("CLOCK_MONOTONIC"));
    for e in ev.iter().filter(|e| e["cat"] == "cpu") {
        let f = e["args"]["frame"].as_u64().unwrap();
        let case = &e["args"]["case"];
        let g = ev
            .iter()
            .find(|g| {
                g["args"]["key"] == "frame" && g["args"]["frame"] == f && &g["args"]["case"] == case
            })
            .unwrap();
        assert!(
            g["ts"].as_f64().unwrap() >= e["ts"].as_f64().unwrap() - 1.0,
            "GPU before CPU: {g} {e}"
        );
    }
    // Without calibration: GPU time only, from the first frame.
    let gpu_only = dir.path().join("gpu.json");
    bench_sort(
        &dir.path().join("b"),
        "5",
        &[(fluidform::gpu::clock::NO_CALIBRATION_ENV, "1")],
        &["--trace", gpu_only.to_str().unwrap()],
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&gpu_only).unwrap()).unwrap();
    assert!(check_nesting(&t) >= 15 * 3);
    let ev = t["traceEvents"].as_array().unwrap();
    assert!(ev.iter().all(|e| e["cat"] != "cpu"));
    let first = ev
        .iter()
        .filter_map(|e| e["ts"].as_f64())
        .fold(f64::INFINITY, f64::min);
    assert_eq!(first, 0.0);
    // A run traces too.
    let run = dir.path().join("run.json");
    let o = fluidform(&[
        "run",
        "--scene",
        "demo",
        "--frames",
        "3",
        "--particles",
        "1024",
        "--width",
        "64",
        "--height",
        "64",
        "--save-every",
        "0",
        "--quiet",
        "--validation",
        "--out",
        dir.path().join("run").to_str().unwrap(),
        "--trace",
        run.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&run).unwrap()).unwrap();
    assert!(check_nesting(&t) >= 3);
}

#[test]
fn experiments_refuse_a_trace() {
    let o = fluidform(&["experiment", "table2", "--quick", "--trace", "x.json"]);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("--trace is for run and bench"),
        "{}",
        text(&o)
    );
}

#[test]
fn verdicts_know_their_noise() {
    use fluidform::experiment::findings::Verdict;
    let iv = |lo: f64, median: f64, hi: f64| Interval {
        median,
        lo,
        hi,
        ..Default::default()
    };
    let (fast, slow, near) = (iv(0.9, 1.0, 1.1), iv(2.0, 2.1, 2.3), iv(1.05, 1.2, 1.4));
    assert_eq!(Verdict::less(&fast, &slow), Verdict::Confirmed);
    assert_eq!(Verdict::less(&slow, &fast), Verdict::Refuted);
    assert_eq!(Verdict::less(&fast, &near), Verdict::Inconclusive);
    // Speed-ups: at least 1.8x for sure, 2x maybe, 2.6x not at all.
    assert_eq!(
        Verdict::ratio_at_least(&slow, &fast, 1.8),
        Verdict::Confirmed
    );
    assert_eq!(
        Verdict::ratio_at_least(&slow, &fast, 2.0),
        Verdict::Inconclusive
    );
    assert_eq!(Verdict::ratio_at_least(&slow, &fast, 2.6), Verdict::Refuted);
    use Verdict::*;
    assert_eq!(Verdict::all([Confirmed, Confirmed]), Confirmed);
    assert_eq!(Verdict::all([Confirmed, Inconclusive]), Inconclusive);
    assert_eq!(Verdict::all([Inconclusive, Refuted]), Refuted);
    assert_eq!(Verdict::all([]), NotMeasured);
}
