//! `bench control`: how fast a control target fills, per adaptive mode (or --adaptive):
//! the built-in `giraffe` (or --scene), played for --frames frames (the cap) with the
//! points view at 64 x 64; time to 90% coverage, final coverage and inside fraction, and
//! the GPU frame time.
use super::{BenchOptions, Row};
use crate::config::Adaptive;
use crate::error::{Error, Result};
use crate::run::{run, RunOptions, RunStats};
use clap::ValueEnum;

pub fn control(opts: &BenchOptions) -> Result<Vec<Row>> {
    let sw = &opts.switches;
    let scene = opts.character.clone().unwrap_or_else(|| "giraffe".into());
    let modes: Vec<Adaptive> = match sw.control.adaptive {
        Some(a) => vec![a],
        None => Adaptive::value_variants().to_vec(),
    };
    let mut rows = Vec::new();
    for mode in modes {
        let mut s = sw.clone();
        s.control.adaptive = Some(mode);
        s.view.render = Some(crate::config::RenderKind::Points);
        s.frame.width = Some(64);
        s.frame.height = Some(64);
        s.common.quiet = true;
        let out = opts.out.join("runs").join(mode.as_str());
        let r = run(&RunOptions {
            scene: scene.clone(),
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
                "bench control: scene {scene} has no [control] target"
            )));
        };
        let last = c.last.clone().unwrap_or_default();
        let main = r
            .summary
            .frame_ms
            .ok_or_else(|| Error::Param("bench control: no timed frames".into()))?;
        let t90 = c
            .time_to_90
            .map(|t| format!("{t:.3}"))
            .unwrap_or_else(|| format!("not in {:.2} s", last.time));
        eprintln!(
            "{:<8} control particles {:>6}  time to 90% {t90}  coverage {:.3}",
            mode.as_str(),
            c.control_particles,
            last.coverage
        );
        rows.push(Row {
            variant: format!("adaptive-{}", mode.as_str()),
            n: c.control_particles as u64,
            main,
            passes: r.summary.pass_ms.0.clone(),
            reps: r.summary.frames as u64,
            extra: vec![
                ("time to 90% s".into(), t90),
                ("final coverage".into(), format!("{:.3}", last.coverage)),
                (
                    "final inside".into(),
                    format!("{:.3}", last.inside_fraction),
                ),
                ("mean coverage".into(), format!("{:.3}", c.mean_coverage)),
                (
                    "simulated s".into(),
                    format!("{:.2}", stats.simulated_seconds),
                ),
            ],
        });
    }
    Ok(rows)
}
