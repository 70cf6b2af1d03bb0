//! `scripts/gpu.sh`, the one command a lent GPU runs: its quick mode on lavapipe (so the
//! script cannot rot between the sessions that have a GPU), its cuts when the budget runs
//! out, its refusals, and `fluidform compare`'s device columns.
mod common;
use common::{fluidform, text};
use std::path::Path;
use std::process::{Command, Output};
use std::time::Instant;

/// `bash scripts/gpu.sh ARGS` with the test's binary and logs under `logs`.
fn gpu_sh(args: &[&str], logs: &Path) -> Output {
    Command::new("bash")
        .arg("scripts/gpu.sh")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("FLUIDFORM_BIN", env!("CARGO_BIN_EXE_fluidform"))
        .env("FLUIDFORM_LOGS", logs)
        .output()
        .expect("spawn bash")
}

/// gpu.md's step rows: (step, status).
fn steps(md: &str) -> Vec<(String, String)> {
    md.lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| step"))
        .map(|l| {
            let c: Vec<&str> = l.split('|').map(str::trim).collect();
            (c[1].to_string(), c[4].to_string())
        })
        .collect()
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("fluidform-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// What each step writes, by its name in gpu.md.
fn files_of(step: &str) -> Vec<String> {
    match step {
        "bench-primitives" => vec!["primitives.md".into(), "scan.csv".into(), "sort.csv".into()],
        "bench-sph" => vec!["sph.md".into(), "sph.csv".into()],
        "bench-render" => vec!["render.md".into(), "render-phong.csv".into()],
        "bench-solvers" => vec!["solvers.md".into(), "solvers.csv".into()],
        "character" => vec!["character.md".into(), "character.png".into()],
        "dambreak" => vec!["dambreak.md".into(), "dambreak.json".into()],
        s => match s.strip_prefix("experiment-") {
            Some(n) => ["csv", "md", "png", "findings.json"]
                .iter()
                .map(|e| format!("{n}.{e}"))
                .chain(["findings.md".to_string()])
                .collect(),
            None => Vec::new(),
        },
    }
}

#[test]
fn quick_mode_runs_every_part_within_its_budget() {
    let root = tmp("gpu-quick");
    let out = root.join("lavapipe");
    let t = Instant::now();
    let o = gpu_sh(
        &["--quick", "--validation", "--out", out.to_str().unwrap()],
        &root.join("logs"),
    );
    let secs = t.elapsed().as_secs_f64();
    assert!(o.status.success(), "{}", text(&o));
    // The budget (150 s) plus the closing pages and the last step's kill grace.
    assert!(secs < 190.0, "took {secs:.0} s");
    let md = std::fs::read_to_string(out.join("gpu.md")).expect("gpu.md");
    let rows = steps(&md);
    let names: Vec<&str> = rows.iter().map(|(n, _)| n.as_str()).collect();
    for part in [
        "bench-primitives",
        "bench-sph",
        "bench-render",
        "bench-solvers",
        "experiment-table8",
        "experiment-fig9",
        "experiment-scaling",
        "character",
        "dambreak",
    ] {
        assert!(names.contains(&part), "gpu.md has no row for {part}:\n{md}");
    }
    let mut ran = 0;
    for (name, status) in &rows {
        assert!(
            ["ran", "cut", "skipped"].contains(&status.as_str()),
            "{name}: {status}\n{md}"
        );
        if status == "ran" {
            ran += 1;
            for f in files_of(name) {
                let p = out.join(&f);
                assert!(
                    p.metadata().map(|m| m.len() > 50).unwrap_or(false),
                    "{name} ran but {} is missing",
                    p.display()
                );
            }
        }
    }
    assert!(ran >= 3, "most steps cut or skipped:\n{md}");
    // Without nvidia-smi (lavapipe's machines): one line says so, and every page says the
    // device's state is not recorded.
    let has_smi = Command::new("sh")
        .args(["-c", "command -v nvidia-smi"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_smi {
        let log = text(&o);
        let said: Vec<&str> = log
            .lines()
            .filter(|l| l.contains("nvidia-smi not found"))
            .collect();
        assert_eq!(said.len(), 1, "{log}");
        assert!(md.contains("Device state: not recorded"), "{md}");
        for (name, status) in &rows {
            let page = match name.strip_prefix("experiment-") {
                Some(n) => format!("{n}.md"),
                None => continue,
            };
            if status == "ran" {
                let text = std::fs::read_to_string(out.join(&page)).unwrap();
                assert!(text.contains("Device state: not recorded"), "{page}");
            }
        }
    }
    // The build that made the pages.
    assert!(md.contains(", commit "), "{md}");
    assert!(std::fs::read_to_string(out.join("devices.txt"))
        .unwrap()
        .contains("fluidform: all required features present"));
    assert!(root.join("devices.md").exists(), "compare did not run");
    assert!(!std::fs::read_dir(&out).unwrap().any(|e| e
        .unwrap()
        .path()
        .extension()
        .is_some_and(|x| x == "tmp")));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_spent_budget_cuts_or_skips_each_step_and_still_writes_the_summary() {
    let root = tmp("gpu-cut");
    let out = root.join("dev");
    let t = Instant::now();
    let o = gpu_sh(
        &[
            "--quick",
            "--budget-s",
            "10",
            "--out",
            out.to_str().unwrap(),
        ],
        &root.join("logs"),
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(t.elapsed().as_secs_f64() < 60.0);
    let md = std::fs::read_to_string(out.join("gpu.md")).expect("gpu.md");
    let rows = steps(&md);
    assert!(rows.len() >= 9, "{md}");
    let stopped = rows
        .iter()
        .filter(|(_, s)| s == "cut" || s == "skipped")
        .count();
    assert!(
        stopped >= 5,
        "a 10 s budget stopped only {stopped} steps:\n{md}"
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.lines()
            .any(|l| l.contains(": skipped, its share is spent")),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn bad_arguments_are_one_line_refusals() {
    let logs = tmp("gpu-args");
    for (args, says) in [
        (
            vec!["--budget-s", "abc"],
            "--budget-s must be a whole number",
        ),
        (vec!["--budget-s", "5"], "at least 10"),
        (vec!["--frames", "3"], "unknown argument '--frames'"),
    ] {
        let o = gpu_sh(&args, &logs);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(says), "{err}");
    }
}

/// Two fake device folders with table2 and findings: devices.md gets a column per device
/// beside the thesis's, and each claim's verdict per device.
#[test]
fn compare_puts_every_device_beside_the_paper() {
    let root = tmp("compare");
    let head = "table,row,list,particles,width,height,reps,median_ms,min_ms,max_ms,fps,speedup_vs_none,list_mb,fragments,fragments_per_metaball,longest_list,pixels_past_loop_budget,thesis_k1_fps,thesis_k2_fps,thesis_k2_speedup_vs_none,thesis_memory_mb";
    for (dev, a_fps, s_fps, verdict) in [
        ("cpu-a", "5.114", "5.459", "confirmed"),
        ("gpu-b", "328.6", "198.0", "refuted"),
    ] {
        let d = root.join(dev);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(
            d.join("table2.csv"),
            format!(
                "{head}\ntable2,\"Phong\",abuffer,2048,512,512,20,1,1,1,{a_fps},1,9,1,1,1,0,45,87,7.9,8.7\n\
                 table2,\"Phong\",sbuffer,2048,512,512,20,1,1,1,{s_fps},1,5,1,1,1,0,52,98,8.9,5.8\n"
            ),
        )
        .unwrap();
        std::fs::write(
            d.join("table2.findings.json"),
            format!(
                r#"{{"experiment":"table2","quick":false,"device":"{dev}","date":"2026-11-26",
                "findings":[{{"claim":"S-buffer faster","verdict":"{verdict}","evidence":"x"}}]}}"#
            ),
        )
        .unwrap();
    }
    // A folder with no table is not a device.
    std::fs::create_dir_all(root.join("readme")).unwrap();
    let o = fluidform(&["compare", "--results", root.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    let md = std::fs::read_to_string(root.join("devices.md")).unwrap();
    assert!(
        md.contains("| claim | [cpu-a](cpu-a/findings.md) | [gpu-b](gpu-b/findings.md) |"),
        "{md}"
    );
    assert!(
        md.contains("| S-buffer faster | confirmed | refuted |"),
        "{md}"
    );
    assert!(
        md.contains("| row | list | thesis fps (GTX 1080 Ti) | cpu-a fps | gpu-b fps |"),
        "{md}"
    );
    assert!(md.contains("| Phong | abuffer | 87 | 5.11 | 329 |"), "{md}");
    assert!(md.contains("| Phong | sbuffer | 98 | 5.46 | 198 |"), "{md}");
    assert!(!md.contains("readme"), "{md}");
    let _ = std::fs::remove_dir_all(&root);
}
