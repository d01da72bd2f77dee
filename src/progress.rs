//! Progress for long phases: a bar on a terminal, a few plain lines
//! otherwise (logs, CI), nothing with `--quiet`.

use crate::render::{Budget, PassReport};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Quiet,
    Plain,
    Bar,
}

impl Mode {
    pub fn detect(quiet: bool) -> Mode {
        if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            Mode::Bar
        } else {
            Mode::Plain
        }
    }
}

/// One phase's progress; `advance` may be called from any thread.
pub struct Phase {
    mode: Mode,
    label: &'static str,
    total: u64,
    done: AtomicU64,
    bar: Option<ProgressBar>,
}

impl Phase {
    pub fn start(mode: Mode, label: &'static str, total: u64) -> Phase {
        let bar = (mode == Mode::Bar).then(|| {
            let bar = ProgressBar::new(total);
            if let Ok(style) =
                ProgressStyle::with_template("{msg:>14} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}")
            {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_message(label);
            bar
        });
        Phase { mode, label, total, done: AtomicU64::new(0), bar }
    }

    pub fn advance(&self, n: u64) {
        let before = self.done.fetch_add(n, Ordering::Relaxed);
        if let Some(bar) = &self.bar {
            bar.inc(n);
        } else if self.mode == Mode::Plain && self.total > 0 {
            let (a, b) = (before * 4 / self.total, (before + n) * 4 / self.total);
            if b > a {
                eprintln!("{}: {}%", self.label, b * 25);
            }
        }
    }

    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Progress of a progressive render: passes done, radii, time left.
pub struct PassDisplay {
    mode: Mode,
    budget: Budget,
    bar: Option<ProgressBar>,
}

impl PassDisplay {
    pub fn new(mode: Mode, budget: Budget) -> Self {
        let bar = (mode == Mode::Bar).then(|| {
            let len = match budget {
                Budget::Passes(n) => n as u64,
                Budget::Seconds(s) => s.ceil() as u64,
            };
            let bar = ProgressBar::new(len);
            if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}") {
                bar.set_style(style.progress_chars("=> "));
            }
            bar
        });
        PassDisplay { mode, budget, bar }
    }

    pub fn update(&self, r: &PassReport) {
        let elapsed = r.elapsed.as_secs_f64();
        let left = match self.budget {
            Budget::Passes(n) => elapsed / r.passes as f64 * (n.saturating_sub(r.passes)) as f64,
            Budget::Seconds(s) => (s - elapsed).max(0.0),
        };
        let msg = format!(
            "pass {:>5}  k {} / radius cap {:.4} (caustic), k {} / {:.4} (global)  {:>7.1} s elapsed  {:>7.1} s left",
            r.passes, r.k_caustic, r.r_caustic, r.k_global, r.r_global, elapsed, left
        );
        match (&self.bar, self.mode) {
            (Some(bar), _) => {
                bar.set_message(msg);
                bar.set_position(match self.budget {
                    Budget::Passes(_) => r.passes as u64,
                    Budget::Seconds(_) => elapsed as u64,
                });
            }
            (None, Mode::Plain) => eprintln!("{msg}"),
            _ => {}
        }
    }

    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
