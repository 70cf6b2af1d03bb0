//! `fluidform compare`: every device's committed results side by side. Each results folder
//! (`results/<device-slug>/`) holds one device's tables; `devices.md` beside them puts each
//! table's main numbers in one column per device next to the paper's, and each finding's
//! verdict per device, wherever more than one device has the table.
use super::findings::{self, Verdict};
use super::{io, write};
use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One table as `devices.md` shows it: rows keyed by `keys`, the paper's columns once, then
/// `metrics` for every device.
struct Spec {
    /// `<file>.csv` in each device folder.
    file: &'static str,
    /// `<page>.md`: where the device's own table is.
    page: &'static str,
    title: &'static str,
    keys: &'static [&'static str],
    paper: &'static [(&'static str, &'static str)],
    metrics: &'static [(&'static str, &'static str)],
}

const THESIS_KEYS: &[&str] = &["row", "list"];
const THESIS_PAPER: &[(&str, &str)] = &[("thesis_k2_fps", "thesis fps (GTX 1080 Ti)")];
const FPS: &[(&str, &str)] = &[("fps", "fps")];
const SWEEP_KEYS: &[&str] = &["variant", "n"];
const MS: &[(&str, &str)] = &[("median_ms", "ms")];

const fn thesis(file: &'static str, title: &'static str) -> Spec {
    Spec {
        file,
        page: file,
        title,
        keys: THESIS_KEYS,
        paper: THESIS_PAPER,
        metrics: FPS,
    }
}

const fn sweep(file: &'static str, page: &'static str, title: &'static str) -> Spec {
    Spec {
        file,
        page,
        title,
        keys: SWEEP_KEYS,
        paper: &[],
        metrics: MS,
    }
}

const SPECS: &[Spec] = &[
    thesis("table2", "Thesis table 2: materials x metaball lists"),
    thesis("table3", "Thesis table 3: density functions"),
    thesis("table4", "Thesis table 4: radius R and threshold T"),
    thesis("table5", "Thesis table 5: refinement steps I"),
    thesis("table6", "Thesis table 6: glass, recursion depth and I"),
    thesis("table7", "Thesis table 7: tinted glass, recursion depth"),
    thesis("table8", "Thesis table 8: particle count N"),
    Spec {
        file: "fig9",
        page: "fig9",
        title: "Seed 002, figure 9: counting grid against hash + bitonic (the paper plots fps at 8K..64K on a GT240M and a GTX 590 and gives no values)",
        keys: SWEEP_KEYS,
        paper: &[],
        metrics: FPS,
    },
    Spec {
        file: "adaptive",
        page: "adaptive",
        title: "Adaptive control pressure: the giraffe's fill",
        keys: &["mode"],
        paper: &[],
        metrics: &[
            ("time_to_80_s", "s to 80%"),
            ("final_coverage", "final coverage"),
        ],
    },
    Spec {
        file: "scaling",
        page: "scaling",
        title: "Scaling in N: SPH step and render frame",
        keys: &["kind", "variant", "n"],
        paper: &[],
        metrics: MS,
    },
    Spec {
        file: "fidelity",
        page: "fidelity",
        title: "Liquid-character fidelity",
        keys: &["scene", "preset"],
        paper: &[],
        metrics: &[("fill_mean", "fill"), ("iou_mean", "IoU")],
    },
    Spec {
        file: "surfaces",
        page: "surfaces",
        title: "Surfaces: metaballs, screen-space, marching cubes",
        keys: &["scene", "surface"],
        paper: &[],
        metrics: &[("render_ms", "ms")],
    },
    Spec {
        file: "lists",
        page: "lists",
        title: "Metaball list modes, builds and marches on the thesis frame and the character",
        keys: &["look", "mode"],
        paper: &[],
        metrics: &[("render_ms", "ms"), ("x_floor", "x floor")],
    },
    Spec {
        file: "surge",
        page: "surge",
        title: "The collapsing column's front against Martin & Moyce (1952)",
        keys: &["solver", "t_star"],
        paper: &[("paper", "Martin & Moyce Z")],
        metrics: &[("front", "Z")],
    },
    Spec {
        file: "solves",
        page: "solves",
        title: "A DFSPH step against a WCSPH step (the dam break at 64K)",
        keys: &["solver", "particles"],
        paper: &[],
        metrics: &[
            ("step_ms", "ms per step"),
            ("dispatches", "dispatches"),
            ("barriers", "barriers"),
            ("empty_dispatches", "empty"),
        ],
    },
    sweep("render-phong", "render", "bench render: thesis frame, Phong"),
    sweep("render-march", "render", "bench march: the march's suspects, Phong, S-buffer"),
    sweep("render-glass", "render", "bench render: thesis frame, glass at depth 3"),
    sweep("render-lipschitz", "render", "bench render: thesis frame, Phong, --march lipschitz"),
    sweep("sph", "sph", "bench sph: one SPH step"),
    Spec {
        file: "solvers",
        page: "solvers",
        title: "bench solvers: the dam break per pressure solver",
        keys: SWEEP_KEYS,
        paper: &[],
        metrics: &[("sim s per GPU s", "sim s per GPU s"), ("mean error %", "error %")],
    },
    sweep("scan", "primitives", "bench scan"),
    sweep("sort", "primitives", "bench sort"),
    sweep("neighbors", "primitives", "bench neighbors"),
];

/// One device's folder.
struct Device {
    slug: String,
    /// Its experiments' findings.json (device name, date, --quick, verdicts).
    saved: Vec<findings::Saved>,
}

impl Device {
    fn quick(&self, file: &str) -> bool {
        self.saved.iter().any(|s| s.experiment == file && s.quick)
    }
}

type Rows = Vec<BTreeMap<String, String>>;

fn read_csv(p: &Path) -> Result<Rows> {
    let bad = |e: csv::Error| Error::Param(format!("{}: {e}", p.display()));
    let mut rd = csv::Reader::from_path(p).map_err(bad)?;
    let head = rd.headers().map_err(bad)?.clone();
    let mut rows = Vec::new();
    for rec in rd.records() {
        let rec = rec.map_err(bad)?;
        rows.push(
            head.iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect(),
        );
    }
    Ok(rows)
}

/// A number to three significant figures or so; text as it is; empty as "-".
fn cell(v: Option<&String>) -> String {
    let Some(v) = v.map(|v| v.trim()).filter(|v| !v.is_empty()) else {
        return "-".into();
    };
    match v.parse::<f64>() {
        Ok(x) if x.fract() == 0.0 && x.abs() < 1e9 => format!("{x:.0}"),
        Ok(x) if x.abs() >= 100.0 => format!("{x:.0}"),
        Ok(x) if x.abs() >= 10.0 => format!("{x:.1}"),
        Ok(x) if x.abs() >= 1.0 => format!("{x:.2}"),
        Ok(x) => format!("{x:.3}"),
        Err(_) => v.replace('|', "/"),
    }
}

fn key(spec: &Spec, row: &BTreeMap<String, String>) -> Vec<String> {
    spec.keys
        .iter()
        .map(|k| row.get(*k).cloned().unwrap_or_default())
        .collect()
}

/// The path of `spec`'s CSV in device `d`'s folder.
fn csv_of(root: &Path, d: &Device, spec: &Spec) -> PathBuf {
    root.join(&d.slug).join(format!("{}.csv", spec.file))
}

/// One table with a column per device and metric, for the devices that have its CSV.
fn table(spec: &Spec, root: &Path, devices: &[&Device]) -> Result<String> {
    let mut have = Vec::new();
    for &d in devices {
        have.push((d, read_csv(&csv_of(root, d, spec))?));
    }
    // Rows in first-seen order over the devices; the paper's numbers from the first that has them.
    let mut order: Vec<Vec<String>> = Vec::new();
    let mut paper: BTreeMap<Vec<String>, &BTreeMap<String, String>> = BTreeMap::new();
    for (_, rows) in &have {
        for r in rows {
            let k = key(spec, r);
            if !order.contains(&k) {
                order.push(k.clone());
            }
            paper.entry(k).or_insert(r);
        }
    }
    let mut md = format!("## {}\n\n|", spec.title);
    let mut cols = 0;
    for k in spec.keys {
        md.push_str(&format!(" {k} |"));
        cols += 1;
    }
    for (_, label) in spec.paper {
        md.push_str(&format!(" {label} |"));
        cols += 1;
    }
    for (d, _) in &have {
        let quick = if d.quick(spec.file) { ", --quick" } else { "" };
        for (_, label) in spec.metrics {
            md.push_str(&format!(" {} {label}{quick} |", d.slug));
            cols += 1;
        }
    }
    md.push_str(&format!("\n|{}\n", "---|".repeat(cols)));
    for k in &order {
        md.push('|');
        for v in k {
            md.push_str(&format!(" {} |", v.replace('|', "/")));
        }
        for (col, _) in spec.paper {
            md.push_str(&format!(" {} |", cell(paper[k].get(*col))));
        }
        for (_, rows) in &have {
            let row = rows.iter().find(|r| &key(spec, r) == k);
            for (col, _) in spec.metrics {
                md.push_str(&format!(" {} |", cell(row.and_then(|r| r.get(*col)))));
            }
        }
        md.push('\n');
    }
    md.push_str(&format!(
        "\nEach device's own table: {}.\n\n",
        have.iter()
            .map(|(d, _)| format!("[{}]({}/{}.md)", d.slug, d.slug, spec.page))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    Ok(md)
}

/// Each claim's overall verdict per device (a device measures a claim when one of its
/// experiments does).
fn verdicts(devices: &[Device]) -> String {
    let with: Vec<&Device> = devices.iter().filter(|d| !d.saved.is_empty()).collect();
    let claims = findings::claims(with.iter().flat_map(|d| &d.saved));
    let mut md = String::from("## The papers' findings per device\n\n| claim |");
    for d in &with {
        md.push_str(&format!(" [{}]({}/findings.md) |", d.slug, d.slug));
    }
    md.push_str(&format!("\n|---|{}\n", "---|".repeat(with.len())));
    for c in claims {
        md.push_str(&format!("| {c} |"));
        for d in &with {
            let vs: Vec<Verdict> = d
                .saved
                .iter()
                .flat_map(|s| s.findings.iter().filter(|f| f.claim == c))
                .map(|f| f.verdict)
                .collect();
            let quick = d
                .saved
                .iter()
                .any(|s| s.quick && s.findings.iter().any(|f| f.claim == c));
            md.push_str(&format!(
                " {}{} |",
                findings::overall(&vs).word(),
                if quick { " (--quick)" } else { "" }
            ));
        }
        md.push('\n');
    }
    md.push('\n');
    md
}

/// Every device folder under `root` (one holding a CSV of `SPECS`), sorted by slug.
fn devices(root: &Path) -> Result<Vec<Device>> {
    let entries = std::fs::read_dir(root).map_err(|e| io(root, e))?;
    let mut out = Vec::new();
    for e in entries {
        let e = e.map_err(|e| io(root, e))?;
        let dir = e.path();
        let has_table = SPECS
            .iter()
            .any(|s| dir.join(format!("{}.csv", s.file)).exists());
        if !dir.is_dir() || !has_table {
            continue;
        }
        out.push(Device {
            slug: e.file_name().to_string_lossy().into_owned(),
            saved: findings::load(&dir)?,
        });
    }
    out.sort_by(|a, b| a.slug.cmp(&b.slug));
    Ok(out)
}

/// Write `<root>/devices.md`; its path.
pub fn write_devices(root: &Path) -> Result<PathBuf> {
    let devs = devices(root)?;
    let mut md = String::from(
        "# Every device side by side\n\nWritten by `fluidform compare` from the results \
         folders beside this file (one per device; `scripts/gpu.sh` fills a GPU's). Each \
         table shows the paper's numbers where it gives them and ours on every device that \
         has the table; tables only one device has are listed at the end. A device's \
         column says --quick where its run was shrunk (not for quoting).\n\n",
    );
    let mut only = Vec::new();
    md.push_str(&verdicts(&devs));
    for spec in SPECS {
        let on: Vec<&Device> = devs
            .iter()
            .filter(|d| csv_of(root, d, spec).exists())
            .collect();
        match on.len() {
            0 => {}
            1 => only.push(format!(
                "- {} ({}): {}\n",
                spec.title, spec.file, on[0].slug
            )),
            _ => md.push_str(&table(spec, root, &on)?),
        }
    }
    if !only.is_empty() {
        md.push_str("## On one device only\n\n");
        md.extend(only);
        md.push('\n');
    }
    let p = root.join("devices.md");
    write(&p, &md)?;
    Ok(p)
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_experiment_has_a_spec() {
        for n in super::super::Experiment::all() {
            assert!(super::SPECS.iter().any(|s| s.file == n.as_str()), "{n}");
        }
    }
}
