//! The papers' qualitative findings, each confirmed or refuted by an experiment's numbers.
//! Every experiment saves its verdicts as `<name>.findings.json`; `findings.md` is rebuilt
//! from all of them, one section per claim.
use super::measure::Measured;
use super::tables::{value, TableDef};
use super::{io, write, Env, Experiment};
use crate::bench::interval::{Estimate, Interval, Standing};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub const ORDER: &str = "S-buffer faster than A-buffer faster than none in every row";
pub const MEMORY: &str = "S-buffer memory below the A-buffer's";
pub const ADAPTIVE: &str = "adaptive control pressure fills the shape faster";
pub const GRID_BEATS: &str = "the counting grid beats hash + bitonic sort";
pub const GRID_LINEAR: &str = "the counting grid scales linearly in N";
/// Issue 59: against the thesis's own GPU (a GTX 1080 Ti has about a sixth of an H200's
/// FP32 rate), every cell the thesis timed on it.
pub const SIXFOLD_K2: &str = "every thesis row at least 6x the GTX 1080 Ti's fps on this device";
/// The fps ratio SIXFOLD_K2 asks for.
pub const K2_FACTOR: f64 = 6.0;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    Confirmed,
    Refuted,
    /// The effect lies inside the noise: the intervals overlap, or a row was flagged.
    Inconclusive,
    NotMeasured,
}

impl Verdict {
    pub fn of(holds: bool) -> Self {
        match holds {
            true => Verdict::Confirmed,
            false => Verdict::Refuted,
        }
    }

    pub fn word(self) -> &'static str {
        match self {
            Verdict::Confirmed => "confirmed",
            Verdict::Refuted => "refuted",
            Verdict::Inconclusive => "inconclusive",
            Verdict::NotMeasured => "not measured",
        }
    }

    /// A claim that `a` takes less time than `b`: confirmed where a's interval lies wholly
    /// below b's, refuted where wholly above, inconclusive where they overlap.
    pub fn less(a: &Interval, b: &Interval) -> Self {
        match a.against(b) {
            Standing::Below => Verdict::Confirmed,
            Standing::Above => Verdict::Refuted,
            Standing::Overlap => Verdict::Inconclusive,
        }
    }

    /// A claim that `slow / fast` is at least `k` (a speed-up): confirmed where even the
    /// least ratio the intervals allow reaches k, refuted where even the greatest does not.
    pub fn ratio_at_least(slow: &Interval, fast: &Interval, k: f64) -> Self {
        if slow.lo / fast.hi.max(1e-12) >= k {
            Verdict::Confirmed
        } else if slow.hi / fast.lo.max(1e-12) < k {
            Verdict::Refuted
        } else {
            Verdict::Inconclusive
        }
    }

    /// `less` on two rows' estimates: inconclusive where either row was flagged.
    pub fn faster(a: &Estimate, b: &Estimate) -> Self {
        match a.flagged || b.flagged {
            true => Verdict::Inconclusive,
            false => Verdict::less(&a.interval, &b.interval),
        }
    }

    /// `ratio_at_least` on two rows' estimates: inconclusive where either was flagged.
    pub fn speedup_at_least(slow: &Estimate, fast: &Estimate, k: f64) -> Self {
        match slow.flagged || fast.flagged {
            true => Verdict::Inconclusive,
            false => Verdict::ratio_at_least(&slow.interval, &fast.interval, k),
        }
    }

    /// A claim over several comparisons ("in every row"): refuted where any is, else
    /// inconclusive where any is, else confirmed; not measured without comparisons.
    pub fn all(verdicts: impl IntoIterator<Item = Verdict>) -> Self {
        overall(&verdicts.into_iter().collect::<Vec<_>>())
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Finding {
    pub claim: String,
    pub verdict: Verdict,
    /// The numbers behind the verdict.
    pub evidence: String,
}

impl Finding {
    pub fn new(claim: &str, verdict: Verdict, evidence: String) -> Self {
        Self {
            claim: claim.into(),
            verdict,
            evidence,
        }
    }
}

/// One experiment's `<name>.findings.json`.
#[derive(Serialize, Deserialize)]
pub struct Saved {
    pub experiment: String,
    pub quick: bool,
    pub device: String,
    pub date: String,
    pub findings: Vec<Finding>,
}

/// Save `<name>.findings.json` with the run's device, date and mode.
pub fn save(env: &Env, name: Experiment, found: &[Finding]) -> Result<()> {
    let s = Saved {
        experiment: name.to_string(),
        quick: env.quick,
        device: env.meta.device.clone(),
        date: env.meta.date.clone(),
        findings: found.to_vec(),
    };
    let text = serde_json::to_string_pretty(&s).map_err(|e| Error::Param(e.to_string()))?;
    write(&env.out.join(format!("{name}.findings.json")), &text)
}

/// Every experiment's saved findings in `dir`, in `Experiment` order.
pub fn load(dir: &Path) -> Result<Vec<Saved>> {
    let mut saved = Vec::new();
    for name in Experiment::all() {
        let p = dir.join(format!("{name}.findings.json"));
        if !p.exists() {
            continue;
        }
        let text = std::fs::read_to_string(&p).map_err(|e| io(&p, e))?;
        let s: Saved = serde_json::from_str(&text)
            .map_err(|e| Error::Param(format!("{}: {e}", p.display())))?;
        saved.push(s);
    }
    Ok(saved)
}

/// A claim's verdict over the experiments that measure it: refuted where any refutes it.
pub fn overall<'a>(verdicts: impl IntoIterator<Item = &'a Verdict>) -> Verdict {
    let measured: Vec<Verdict> = verdicts
        .into_iter()
        .copied()
        .filter(|v| *v != Verdict::NotMeasured)
        .collect();
    if measured.is_empty() {
        Verdict::NotMeasured
    } else if measured.contains(&Verdict::Refuted) {
        Verdict::Refuted
    } else if measured.contains(&Verdict::Inconclusive) {
        Verdict::Inconclusive
    } else {
        Verdict::Confirmed
    }
}

/// Every claim the saved findings speak of, in first-seen order.
pub fn claims<'a>(saved: impl IntoIterator<Item = &'a Saved>) -> Vec<&'a str> {
    let mut claims: Vec<&str> = Vec::new();
    for s in saved {
        for f in &s.findings {
            if !claims.contains(&f.claim.as_str()) {
                claims.push(&f.claim);
            }
        }
    }
    claims
}

/// findings.md from every `<name>.findings.json` in the output directory.
pub fn rebuild(env: &Env) -> Result<PathBuf> {
    let saved = load(&env.out)?;
    let claims = claims(&saved);
    let mut md = format!(
        "# The papers' findings on {}\n\nWritten by `fluidform experiment`: each claim of the \
         papers, confirmed or refuted by the experiments that measure it (their tables are \
         beside this file). A comparison counts only where the two rows' 95% intervals do not \
         overlap; where they do, or where a row was flagged as measured in a drifting device \
         state, it is inconclusive. A claim is refuted where any experiment refutes it, else \
         inconclusive where any is. Every device's \
         verdicts side by side: `fluidform compare` writes them to ../devices.md.\n\n",
        env.meta.device
    );
    for &c in &claims {
        let all: Vec<(&Saved, &Finding)> = saved
            .iter()
            .flat_map(|s| {
                s.findings
                    .iter()
                    .filter(|f| f.claim == c)
                    .map(move |f| (s, f))
            })
            .collect();
        let overall = overall(all.iter().map(|(_, f)| &f.verdict));
        md.push_str(&format!("## {c}: **{}**\n\n", overall.word()));
        for (s, f) in all {
            md.push_str(&format!(
                "- [{}]({}.md) ({}{}): {}. {}\n",
                s.experiment,
                s.experiment,
                match s.date.is_empty() {
                    true => "date not recorded".to_string(),
                    false => s.date.clone(),
                },
                if s.quick { ", --quick" } else { "" },
                f.verdict.word(),
                f.evidence
            ));
        }
        md.push('\n');
    }
    md.push_str(&env.meta.markdown(env));
    let p = env.out.join("findings.md");
    write(&p, &md)?;
    Ok(p)
}

/// Every cell with a GTX 1080 Ti (K2) frame rate in the thesis at least K2_FACTOR times it
/// here, beyond the cell's interval: confirmed where even its slowest bound is fast enough,
/// refuted where even its fastest is not, inconclusive between or where flagged.
pub fn sixfold_k2(def: &TableDef, m: &Measured) -> Finding {
    let (mut verdicts, mut ratios, mut short) = (Vec::new(), Vec::new(), Vec::new());
    for (r, row) in def.rows.iter().enumerate() {
        for (k, col) in def.cols.iter().enumerate() {
            let Some(k2) = row.thesis.get(k).and_then(|t| value(t.k2)) else {
                continue;
            };
            let c = &m.cells[r][k];
            let need_ms = 1000.0 / (K2_FACTOR * k2);
            let i = &c.est.interval;
            let v = match (c.est.flagged, i.hi <= need_ms, i.lo > need_ms) {
                (true, _, _) => Verdict::Inconclusive,
                (false, true, _) => Verdict::Confirmed,
                (false, _, true) => Verdict::Refuted,
                _ => Verdict::Inconclusive,
            };
            let ratio = c.fps / k2;
            ratios.push(ratio);
            if v != Verdict::Confirmed {
                short.push(format!(
                    "{} {} {:.1} fps = {ratio:.2}x its {k2}",
                    m.labels[r], col.name, c.fps
                ));
            }
            verdicts.push(v);
        }
    }
    let n = verdicts.len();
    Finding::new(
        SIXFOLD_K2,
        Verdict::all(verdicts),
        format!(
            "{} of {n} cells at least {}x beyond their intervals; fps over the thesis's \
             GTX 1080 Ti {:.2}x to {:.2}x{}",
            n - short.len(),
            K2_FACTOR,
            ratios.iter().cloned().fold(f64::INFINITY, f64::min),
            ratios.iter().cloned().fold(0.0, f64::max),
            match short.is_empty() {
                true => String::new(),
                false => format!(" (not: {})", short.join("; ")),
            }
        ),
    )
}
