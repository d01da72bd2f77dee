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

/// Seconds more a progressive render needs to reach its `--target-error`
/// (None: no target, or no prediction yet). Noise falls as the square root
/// of the passes: the passes the worst region needs, from its error now, at
/// the time per pass so far.
pub fn seconds_to_target(budget: &Budget, r: &PassReport) -> Option<f64> {
    let target = budget.target_error?;
    let per_pass = r.elapsed.as_secs_f64() / r.rendered.max(1) as f64;
    let worst = r.predictions.iter().skip((!budget.windows.is_empty()) as usize);
    let e = worst.map(|(_, p)| p.relative_rmse()).reduce(f64::max)?;
    let need = r.passes as f64 * (e / target).powi(2);
    Some(per_pass * (need - r.passes as f64).max(0.0))
}

/// Progress of a progressive render: passes done, radii, predicted
/// error, time left.
pub struct PassDisplay {
    mode: Mode,
    budget: Budget,
    first: u32,
    bar: Option<ProgressBar>,
    last_line: std::cell::Cell<Option<std::time::Instant>>,
}

impl PassDisplay {
    /// `first`: the first pass this run renders (a resumed render's passes
    /// before it are done already).
    pub fn new(mode: Mode, budget: Budget, first: u32) -> Self {
        let bar = (mode == Mode::Bar).then(|| {
            let bar = match (budget.end, budget.seconds) {
                (Some(n), _) => ProgressBar::new(n.saturating_sub(first) as u64),
                (None, Some(s)) => ProgressBar::new(s.ceil() as u64),
                (None, None) => ProgressBar::new_spinner(),
            };
            if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}") {
                bar.set_style(style.progress_chars("=> "));
            }
            bar
        });
        PassDisplay { mode, budget, first, bar, last_line: std::cell::Cell::new(None) }
    }

    /// Seconds left by the budget's nearest limit (None: unknown yet).
    fn left(&self, r: &PassReport) -> Option<f64> {
        let elapsed = r.elapsed.as_secs_f64();
        let per_pass = elapsed / r.rendered.max(1) as f64;
        let mut left: Option<f64> = None;
        let mut take = |v: f64| left = Some(left.map_or(v, |l: f64| l.min(v)));
        if let Some(end) = self.budget.end {
            take(per_pass * end.saturating_sub(self.first + r.rendered) as f64);
        }
        if let Some(s) = self.budget.seconds {
            take((s - elapsed).max(0.0));
        }
        if let Some(more) = seconds_to_target(&self.budget, r) {
            take(more);
        }
        left
    }

    pub fn update(&self, r: &PassReport) {
        let elapsed = r.elapsed.as_secs_f64();
        let mut msg = format!("pass {:>5}  radius cap {:.4} caustic, {:.4} global", r.passes, r.r_caustic, r.r_global);
        for (name, p) in &r.predictions {
            msg += &format!("  {name} ±{:.1}%", 100.0 * p.relative_rmse());
        }
        msg += &format!("  {elapsed:.1} s");
        if let Some(left) = self.left(r) {
            msg += &format!(", ~{left:.0} s left");
        }
        match (&self.bar, self.mode) {
            (Some(bar), _) => {
                bar.set_message(msg);
                bar.set_position(match (self.budget.end, self.budget.seconds) {
                    (Some(_), _) => r.rendered as u64,
                    (None, Some(_)) => elapsed as u64,
                    (None, None) => r.passes as u64,
                });
            }
            (None, Mode::Plain) => {
                // A line every few seconds: logs stay readable at any pass rate.
                let now = std::time::Instant::now();
                if self.last_line.get().is_none_or(|t| now.duration_since(t).as_secs_f64() >= 2.0) {
                    eprintln!("{msg}");
                    self.last_line.set(Some(now));
                }
            }
            _ => {}
        }
    }

    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}

/// A line for a wait of unknown length (loading a scene): said once the
/// wait passes a second, so a long load is not silent, and closed with its
/// time. Nothing is said for a short wait or with `--quiet`.
pub struct Wait {
    done: Option<std::sync::mpsc::Sender<()>>,
    said: Option<std::thread::JoinHandle<bool>>,
    start: std::time::Instant,
    what: String,
}

impl Wait {
    /// After this long a wait is said.
    pub const AFTER: std::time::Duration = std::time::Duration::from_secs(1);

    /// `what`: the wait's subject, e.g. "loading scenes/big.toml (9.2 MB)".
    pub fn start(mode: Mode, what: String) -> Wait {
        let (done, finished) = std::sync::mpsc::channel::<()>();
        let line = what.clone();
        let said = (mode != Mode::Quiet).then(|| {
            std::thread::spawn(move || match finished.recv_timeout(Self::AFTER) {
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    eprintln!("{line} ...");
                    true
                }
                _ => false,
            })
        });
        Wait { done: Some(done), said, start: std::time::Instant::now(), what }
    }

    /// Ends the wait; if it was said, says how long it took.
    pub fn finish(mut self) {
        self.done.take();
        if self.said.take().is_some_and(|t| t.join().unwrap_or(false)) {
            eprintln!("{}: done in {:.1} s", self.what, self.start.elapsed().as_secs_f64());
        }
    }
}
