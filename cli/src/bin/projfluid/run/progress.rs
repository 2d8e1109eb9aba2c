//! Progress of a run on stderr: a bar on a terminal, else a line about every 10 %.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use projfluid_lab::driver::{RunLength, StepReport};
use std::io::IsTerminal;

/// Progress on stderr: a bar on a terminal, else a line about every 10 % of the run.
pub(super) struct Progress {
    bar: Option<ProgressBar>,
    next_tenth: u32,
    steps: u64,
    wall: f64,
    outer: u64,
}

impl Progress {
    pub(super) fn new(target: RunLength) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template(
                "{bar:20.cyan/blue} {percent:>3}% {elapsed:>4} {wide_msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            if let RunLength::Steps(n) = target {
                bar.set_message(format!("0/{n} steps"));
            }
            bar
        });
        Self {
            bar,
            next_tenth: 1,
            steps: 0,
            wall: 0.0,
            outer: 0,
        }
    }

    /// Records a finished step.
    pub(super) fn update(&mut self, report: &StepReport<'_>) {
        self.steps += 1;
        self.wall += report.wall_seconds;
        self.outer += report.stats.outer_iterations as u64;
        let n = self.steps as f64;
        let (t, ms, outer) = (
            report.world.time(),
            self.wall * 1e3 / n,
            self.outer as f64 / n,
        );
        let done = report.done;
        match &self.bar {
            Some(bar) => {
                bar.set_position((done * 1000.0).round() as u64);
                bar.set_message(format!(
                    "t={t:.3}s step {} {ms:.1} ms/step {outer:.1} outer it.",
                    self.steps
                ));
            }
            None if done * 10.0 >= f64::from(self.next_tenth) - 1e-9 => {
                eprintln!(
                    "{:>3.0}%  t = {t:.4} s, step {}, {ms:.1} ms/step, {outer:.1} outer iterations/step",
                    done * 100.0,
                    self.steps
                );
                while f64::from(self.next_tenth) <= done * 10.0 + 1e-9 {
                    self.next_tenth += 1;
                }
            }
            None => {}
        }
    }

    pub(super) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish();
        }
    }
}
