//! The observers of a progressive render that the programs choose from:
//! the progress of the passes, the --target-error watch, the tev preview,
//! the outputs rewritten every so often.

use super::checks::WEEK;
use crate::display::Tev;
use crate::error::Error;
use crate::output::partial::Part;
use crate::progress::{Bar, Mode};
use crate::render::{Budget, Observer, PassReport};
use std::ops::ControlFlow;
use std::time::Instant;

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
    bar: Option<Bar>,
    last_line: Option<Instant>,
}

impl PassDisplay {
    /// `first`: the first pass this run renders (a resumed render's passes
    /// before it are done already).
    pub fn new(mode: Mode, budget: Budget, first: u32) -> Self {
        let bar = (mode == Mode::Bar).then(|| match (budget.end, budget.seconds) {
            (Some(n), _) => Bar::new(Some(n.saturating_sub(first) as u64)),
            (None, Some(s)) => Bar::new(Some(s.ceil() as u64)),
            (None, None) => Bar::new(None),
        });
        PassDisplay { mode, budget, first, bar, last_line: None }
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
}

impl Observer for PassDisplay {
    fn pass(&mut self, r: &PassReport) -> ControlFlow<()> {
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
                bar.show(
                    msg,
                    match (self.budget.end, self.budget.seconds) {
                        (Some(_), _) => r.rendered as u64,
                        (None, Some(_)) => elapsed as u64,
                        (None, None) => r.passes as u64,
                    },
                );
            }
            (None, Mode::Plain) => {
                // A line every few seconds: logs stay readable at any pass rate.
                let now = Instant::now();
                if self.last_line.is_none_or(|t| now.duration_since(t).as_secs_f64() >= 2.0) {
                    eprintln!("{msg}");
                    self.last_line = Some(now);
                }
            }
            _ => {}
        }
        ControlFlow::Continue(())
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish();
        }
    }
}

/// Says once that --target-error will not be reached within the run's
/// time (--time, or the week a run may last), as soon as a prediction shows
/// it.
pub struct TargetWatch {
    pub budget: Budget,
    pub quiet: bool,
    pub said: bool,
}

impl Observer for TargetWatch {
    fn pass(&mut self, report: &PassReport) -> ControlFlow<()> {
        if self.said || self.quiet {
            return ControlFlow::Continue(());
        }
        let budget = &self.budget;
        let (Some(more), Some(seconds)) = (seconds_to_target(budget, report), budget.seconds) else {
            return ControlFlow::Continue(());
        };
        if more > seconds - report.elapsed.as_secs_f64() {
            self.said = true;
            let limit = if seconds == WEEK {
                format!("after a week ({WEEK} s, the longest run; --time stops it sooner)")
            } else {
                format!("at --time {seconds} s")
            };
            eprintln!(
                "photonmap: warning: --target-error {:e}: about {more:.2e} s more would be needed (the error \
                 falls as one over the square root of the passes); the render stops {limit} or at Ctrl-C, \
                 keeping the passes done",
                budget.target_error.unwrap_or(0.0)
            );
        }
        ControlFlow::Continue(())
    }
}

/// Each pass shown in the tev viewer; a viewer that goes away is said
/// once, and the render goes on without it.
pub struct TevPreview {
    tev: Option<Tev>,
}

impl TevPreview {
    pub fn connect(address: &str, width: u32, height: u32) -> Result<TevPreview, Error> {
        let tev = Tev::connect(address, "photonmap", width, height)
            .map_err(|e| Error::Invalid(format!("--display {address}: cannot reach tev: {e}")))?;
        Ok(TevPreview { tev: Some(tev) })
    }
}

impl Observer for TevPreview {
    fn pass(&mut self, report: &PassReport) -> ControlFlow<()> {
        if let Some(t) = &mut self.tev {
            if let Err(e) = t.update(report.film) {
                eprintln!("photonmap: warning: --display: {e}; the render goes on without it");
                self.tev = None;
            }
        }
        ControlFlow::Continue(())
    }
}

/// The outputs (and the partial of this run's passes) rewritten at most
/// every `every` seconds, so a run that dies keeps an image of its passes
/// so far. A write that fails (a full disk, a directory gone) is said and
/// tried again at the next one and at the end: the passes are still in
/// memory, and stopping would lose them.
pub struct PeriodicWriter<W> {
    pub every: f64,
    pub last: Instant,
    /// The first pass this run renders.
    pub first: u32,
    /// When the run started (a part's seconds count from it).
    pub start: Instant,
    /// Writes the outputs of a report, this run's passes being `part`.
    pub write: W,
}

impl<W: FnMut(&PassReport, &Part) -> Result<(), Error>> Observer for PeriodicWriter<W> {
    fn pass(&mut self, report: &PassReport) -> ControlFlow<()> {
        if self.last.elapsed().as_secs_f64() > self.every {
            let part = Part {
                passes: format!("{}..{}", self.first, self.first + report.rendered),
                photons: report.photons,
                seconds: self.start.elapsed().as_secs_f64(),
            };
            if let Err(e) = (self.write)(report, &part) {
                eprintln!("photonmap: warning: {e}; the render goes on and writes again in {} s", self.every);
            }
            self.last = Instant::now();
        }
        ControlFlow::Continue(())
    }
}
