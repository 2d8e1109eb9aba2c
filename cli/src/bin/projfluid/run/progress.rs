//! Progress of a run on stderr: a bar on a terminal, else a line about every 10 %.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use projfluid_lab::driver::{RunLength, StepReport};
use std::io::{IsTerminal, Write};

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
        let bar = std::io::stderr()
            .is_terminal()
            .then(|| ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr()));
        Self::with_bar(target, bar)
    }

    /// Progress shown on `bar` (permille of the run), or as lines on stderr when `None`.
    fn with_bar(target: RunLength, bar: Option<ProgressBar>) -> Self {
        if let Some(bar) = &bar {
            let style = ProgressStyle::with_template(
                "{bar:20.cyan/blue} {percent:>3}% {elapsed:>4} {wide_msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            if let RunLength::Steps(n) = target {
                bar.set_message(format!("0/{n} steps"));
            }
        }
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

    /// Draws the bar's final state and ends its line on stderr, so that what follows (the
    /// run's summary) starts on a line of its own.
    pub(super) fn finish(&self) {
        self.finish_on(&mut std::io::stderr());
    }

    /// As `finish`, the bar drawing on the terminal that `terminal` writes to.
    fn finish_on(&self, terminal: &mut impl Write) {
        if let Some(bar) = &self.bar {
            bar.finish();
            // indicatif leaves the cursor after the bar, on the bar's line, counting on the
            // terminal to wrap the next character written.
            let _ = writeln!(terminal);
            let _ = terminal.flush();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use indicatif::TermLike;
    use std::sync::{Arc, Mutex};

    /// A terminal 60 columns wide that records what is written to it; cursor movements
    /// and clearing are not recorded.
    #[derive(Clone, Debug, Default)]
    struct Screen(Arc<Mutex<String>>);

    impl Screen {
        fn text(&self) -> String {
            self.0.lock().unwrap().clone()
        }
    }

    impl TermLike for Screen {
        fn width(&self) -> u16 {
            60
        }
        fn move_cursor_up(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_down(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_right(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_left(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn write_line(&self, s: &str) -> std::io::Result<()> {
            self.write_str(&format!("{s}\n"))
        }
        fn write_str(&self, s: &str) -> std::io::Result<()> {
            self.0.lock().unwrap().push_str(s);
            Ok(())
        }
        fn clear_line(&self) -> std::io::Result<()> {
            Ok(())
        }
        fn flush(&self) -> std::io::Result<()> {
            Ok(())
        }
    }

    impl Write for Screen {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.write_str(&String::from_utf8_lossy(buf))?;
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_finished_bar_ends_its_line_before_the_summary() {
        let mut screen = Screen::default();
        let target = ProgressDrawTarget::term_like(Box::new(screen.clone()));
        let bar = ProgressBar::with_draw_target(Some(1000), target);
        let progress = Progress::with_bar(RunLength::Steps(40), Some(bar));
        progress.finish_on(&mut screen);
        write!(screen, "scene  dam_break").unwrap();
        let text = screen.text();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines.last(),
            Some(&"scene  dam_break"),
            "the summary is glued to the bar: {text:?}"
        );
        let bar_line = lines[lines.len() - 2];
        assert!(
            bar_line.contains("100%") && bar_line.contains("0/40 steps"),
            "the bar's final state is drawn: {text:?}"
        );
    }

    #[test]
    fn without_a_terminal_finishing_writes_nothing() {
        let mut screen = Screen::default();
        Progress::with_bar(RunLength::Steps(40), None).finish_on(&mut screen);
        assert_eq!(screen.text(), "");
    }
}
