//! Progress for long phases: a bar on a terminal, a few plain lines
//! otherwise (logs, CI), nothing with `--quiet`.

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

/// A bar of a progressive render's passes: a message and a position of a
/// known length, or a spinner.
pub struct Bar(ProgressBar);

impl Bar {
    pub fn new(len: Option<u64>) -> Bar {
        let bar = match len {
            Some(n) => ProgressBar::new(n),
            None => ProgressBar::new_spinner(),
        };
        if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}") {
            bar.set_style(style.progress_chars("=> "));
        }
        Bar(bar)
    }

    pub fn show(&self, message: String, position: u64) {
        self.0.set_message(message);
        self.0.set_position(position);
    }

    pub fn finish(self) {
        self.0.finish_and_clear();
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
