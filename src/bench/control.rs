//! `bench control`: how fast and how well a control target fills, per adaptive mode (or
//! --adaptive) and velocity gain (--velocities, or --control-velocity, or 0): the built-in
//! `giraffe` (or --scene), played for --frames frames (the cap) with the points view at
//! 64 x 64; times to 80% and 90% coverage, final coverage and inside fraction, the mean
//! inside fraction over the last animation cycle, the share of the frame the rays
//! placement takes (with --placement rays), and the GPU frame time.
use super::{BenchOptions, Row};
use crate::control::Adaptive;
use crate::error::{Error, Result};
use crate::run::{run, RunOptions, RunStats};

fn secs(t: Option<f64>, last: f64) -> String {
    t.map(|t| format!("{t:.3}"))
        .unwrap_or_else(|| format!("not in {last:.2} s"))
}

pub fn control(opts: &BenchOptions) -> Result<Vec<Row>> {
    let sw = &opts.switches;
    let scene = opts.character.clone().unwrap_or_else(|| "giraffe".into());
    let modes: Vec<Adaptive> = match sw.control.adaptive {
        Some(a) => vec![a],
        None => Adaptive::all().to_vec(),
    };
    let velocities = match (&opts.velocities[..], sw.control.control_velocity) {
        ([], k) => vec![k.unwrap_or(0.0)],
        (_, Some(_)) => {
            return Err(Error::Param(
                "bench control takes --velocities or --control-velocity, not both".into(),
            ))
        }
        (v, None) => v.to_vec(),
    };
    let mut rows = Vec::new();
    let mut series = Vec::new();
    let mut device = String::new();
    for mode in modes {
        for &k in &velocities {
            let variant = match velocities.len() {
                1 if k == 0.0 => format!("adaptive-{}", mode.as_str()),
                _ => format!("adaptive-{}-velocity-{k}", mode.as_str()),
            };
            let (row, dev, cov) = one_run(opts, &scene, &variant, mode, k)?;
            device = dev;
            series.push((variant, cov));
            rows.push(row);
        }
    }
    super::plot::coverage(
        &opts.out.join("coverage.png"),
        &format!("bench control, {scene}"),
        &device,
        &series,
    )?;
    Ok(rows)
}

/// Coverage over time: (scene time, coverage).
type Coverage = Vec<(f64, f64)>;

/// One run of the scene with adaptive mode `mode` and velocity gain `k`: its row, the
/// device's name and the coverage over time. Long because its row lists every measured
/// column.
fn one_run(
    opts: &BenchOptions,
    scene: &str,
    variant: &str,
    mode: Adaptive,
    k: f32,
) -> Result<(Row, String, Coverage)> {
    let mut s = opts.switches.clone();
    s.control.adaptive = Some(mode);
    s.control.control_velocity = Some(k);
    s.view.render = Some(crate::render::RenderKind::Points);
    s.frame.width = Some(64);
    s.frame.height = Some(64);
    s.common.quiet = true;
    let out = opts.out.join("runs").join(variant);
    let r = run(&RunOptions {
        scene: scene.to_string(),
        frames: Some(opts.frames),
        out,
        save_every: 0,
        switches: s,
    })?;
    let RunStats::Sph(stats) = &r.summary.stats else {
        return Err(Error::Param(format!(
            "bench control: scene {scene} has no fluid"
        )));
    };
    let Some(c) = stats.control.as_ref().and_then(|c| c.targets.first()) else {
        return Err(Error::Param(format!(
            "bench control: scene {scene} has no control target"
        )));
    };
    let last = c.last.clone().unwrap_or_default();
    let csv = opts.out.join("runs").join(variant).join("control.csv");
    let coverage = coverage_of(&csv, &c.target)?;
    let main = r
        .summary
        .frame_ms
        .ok_or_else(|| Error::Param("bench control: no timed frames".into()))?;
    let passes = r.summary.pass_ms.0.clone();
    let place = passes
        .iter()
        .find(|(k, _)| k.ends_with("/place"))
        .map(|(_, p)| format!("{:.1}%", 100.0 * p.median / main.median))
        .unwrap_or_else(|| "-".into());
    let cycle = c
        .mean_inside_last_cycle
        .map(|m| format!("{m:.3}"))
        .unwrap_or_else(|| match c.cycle_s {
            Some(t) => format!("run < cycle {t:.2} s"),
            None => "no clip".into(),
        });
    eprintln!(
        "{variant:<28} control particles {:>6}  coverage to 80% {}  to 90% {}  coverage {:.3}  fill {:.3}  fill to 90% {}  inside over the last cycle {cycle}",
        c.control_particles,
        secs(c.coverage_time_to_80, last.time),
        secs(c.coverage_time_to_90, last.time),
        last.coverage,
        last.fill,
        secs(c.time_to_90, last.time),
    );
    let row = Row {
        interval: None,
        flagged: false,
        variant: variant.to_string(),
        n: c.control_particles as u64,
        main,
        passes,
        reps: r.summary.frames as u64,
        extra: vec![
            (
                "time to 80% s".into(),
                secs(c.coverage_time_to_80, last.time),
            ),
            (
                "time to 90% s".into(),
                secs(c.coverage_time_to_90, last.time),
            ),
            ("fill to 90% s".into(), secs(c.time_to_90, last.time)),
            ("final fill".into(), format!("{:.3}", last.fill)),
            ("final coverage".into(), format!("{:.3}", last.coverage)),
            (
                "final inside".into(),
                format!("{:.3}", last.inside_fraction),
            ),
            ("inside last cycle".into(), cycle),
            ("mean coverage".into(), format!("{:.3}", c.mean_coverage)),
            ("place share".into(), place),
            (
                "frames out of band".into(),
                c.frames_out_of_band.to_string(),
            ),
            (
                "simulated s".into(),
                format!("{:.2}", stats.simulated_seconds),
            ),
        ],
    };
    Ok((row, r.summary.device.name.clone(), coverage))
}

/// (time, coverage) of `target` from a run's control.csv.
pub fn coverage_of(path: &std::path::Path, target: &str) -> Result<Vec<(f64, f64)>> {
    let io = |e: csv::Error| Error::Param(format!("{}: {e}", path.display()));
    let mut r = csv::Reader::from_path(path).map_err(io)?;
    let mut out = Vec::new();
    for row in r.deserialize::<crate::control::metrics::ControlRow>() {
        let row = row.map_err(io)?;
        if row.target == target {
            out.push((row.time, row.coverage));
        }
    }
    Ok(out)
}
