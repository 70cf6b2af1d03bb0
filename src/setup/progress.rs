//! Progress of a run: a bar with frames done, rate and ETA on a terminal (indicatif), a
//! plain line about every 10 s otherwise (CI logs), nothing with `--quiet`.
use crate::error::Result;
use crate::gpu::vk;
use crate::gpu::{Context, FrameWork, Profiler};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Seconds between plain progress lines.
const PLAIN_EVERY: Duration = Duration::from_secs(10);

pub struct Progress {
    bar: Option<ProgressBar>,
    plain: bool,
    what: String,
    total: u64,
    done: u64,
    start: Instant,
    last_line: Instant,
}

impl Progress {
    pub fn new(what: &str, total: u64, quiet: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let bar = (!quiet && terminal).then(|| {
            let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(
                    "{msg} {bar:30} {pos}/{len} frames, {per_sec}, ETA {eta}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b.set_message(what.to_string());
            b
        });
        Self {
            bar,
            plain: !quiet && !terminal,
            what: what.to_string(),
            total,
            done: 0,
            start: Instant::now(),
            last_line: Instant::now(),
        }
    }

    /// One more frame done.
    pub fn tick(&mut self) {
        self.done += 1;
        if let Some(b) = &self.bar {
            b.set_position(self.done);
        }
        if self.plain && (self.last_line.elapsed() >= PLAIN_EVERY || self.done == self.total) {
            self.last_line = Instant::now();
            let secs = self.start.elapsed().as_secs_f64();
            let rate = self.done as f64 / secs.max(1e-9);
            let eta = (self.total - self.done) as f64 / rate.max(1e-9);
            eprintln!(
                "{}: frame {}/{} ({rate:.2} frames/s, ETA {eta:.0} s)",
                self.what, self.done, self.total
            );
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// A `FrameWork` that reports each retired frame to a `Progress`.
pub struct Reporting<'a> {
    pub work: &'a mut dyn FrameWork,
    pub progress: Progress,
}

impl FrameWork for Reporting<'_> {
    fn record(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        prof: &mut Profiler,
        frame: u64,
        slot: usize,
    ) -> Result<()> {
        self.work.record(ctx, cmd, prof, frame, slot)
    }

    fn retire(&mut self, ctx: &Context, frame: u64, slot: usize) -> Result<()> {
        self.work.retire(ctx, frame, slot)?;
        self.progress.tick();
        Ok(())
    }
}
