//! The render driver: runs a render method's passes as a [`Plan`] says
//! (one pass as rendered, or passes averaged: a new render, a range of
//! passes for a partial, more passes on a partial's sums) within a
//! [`Budget`] (passes, time, a target error), and reports each pass to
//! [`Observer`]s (progress, previews, periodic writes, a caller's stop).
//!
//! Progressive rendering: independent passes, averaged. Each
//! photon-mapping pass has its own photons and narrower estimates than the
//! pass before ([`super::photon_stage::Estimates::progressive`]), so the
//! average converges to the true image. A pass depends only on its index
//! (random streams are keyed by pass, the radius schedule is global), and
//! the passes' sums are exact ([`crate::film::accumulation`]): any set of passes
//! can be rendered anywhere, in any order, and added into the same image as
//! one process would make.

use super::error_estimate::{ErrorEstimate, Prediction};
use super::method::RenderMethod;
use super::render_pass;
use super::Guide;
use crate::film::accumulation::Accumulation;
use crate::film::Film;
use crate::interrupt;
use crate::metrics::Window;
use crate::progress::Mode;
use crate::render::settings::Settings;
use crate::scene::Scene;
use crate::stats::Stats;
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

/// When a progressive render stops: the first of its limits reached (at
/// least one pass always runs).
#[derive(Clone, Debug, Default)]
pub struct Budget {
    /// Stop before this pass index.
    pub end: Option<u32>,
    /// Wall-clock seconds: no pass starts that the last pass's duration says
    /// would end past them.
    pub seconds: Option<f64>,
    /// Stop when the predicted relative RMSE (of every window in `windows`,
    /// or of the whole image when there are none) is below this.
    pub target_error: Option<f64>,
    /// Regions whose predicted error each pass reports.
    pub windows: Vec<Window>,
}

impl Budget {
    pub fn passes(n: u32) -> Budget {
        Budget { end: Some(n), ..Budget::default() }
    }

    pub fn seconds(s: f64) -> Budget {
        Budget { seconds: Some(s), ..Budget::default() }
    }
}

/// Passes a target error is not trusted before: the error estimate's noise
/// part rests on the spread of the passes, which needs a few of them.
pub const MIN_PASSES_FOR_TARGET: u32 = 4;

/// Why a progressive render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stopped {
    Passes,
    Time,
    TargetError,
    /// SIGINT or SIGTERM ([`crate::interrupt`]): the passes finished are kept.
    Interrupted,
    /// The caller's `on_pass` said stop.
    Caller,
}

/// The state of a progressive render after a pass, for progress displays
/// and periodic output.
pub struct PassReport<'a> {
    pub film: &'a Film,
    pub accumulation: &'a Accumulation,
    /// Passes in the image (those resumed from included).
    pub passes: u32,
    /// Passes rendered by this run.
    pub rendered: u32,
    pub elapsed: Duration,
    /// Photons emitted by this run (global and caustic).
    pub photons: u64,
    pub r_caustic: f32,
    pub r_global: f32,
    pub k_caustic: usize,
    pub k_global: usize,
    /// The error estimate, once there are passes enough for one.
    pub error: Option<&'a ErrorEstimate>,
    /// The predicted error of the whole image, then of each window.
    pub predictions: Vec<(String, Prediction)>,
}

/// What a run renders.
pub struct Plan {
    /// Passes averaged into exact sums (progressive), or one pass whose
    /// film is the image as rendered (a classic render).
    pub progressive: bool,
    /// The sums the passes are added to: empty, or a partial's (resumed).
    pub start: Accumulation,
    /// The first pass rendered.
    pub first: u32,
    pub budget: Budget,
}

impl Plan {
    /// A classic render: pass 0, as rendered.
    pub fn single(width: u32, height: u32) -> Plan {
        Plan { progressive: false, start: Accumulation::new(width, height), first: 0, budget: Budget::passes(1) }
    }

    /// A progressive render from pass `first` on, added to `start`, until
    /// `budget` says stop.
    pub fn passes(start: Accumulation, first: u32, budget: Budget) -> Plan {
        Plan { progressive: true, start, first, budget }
    }
}

/// Sees each pass of a progressive render; may stop it.
pub trait Observer {
    /// After each pass, the running average and its estimate.
    fn pass(&mut self, report: &PassReport) -> ControlFlow<()>;

    /// The render has stopped (a display closes).
    fn finish(&mut self) {}
}

impl<F: FnMut(&PassReport) -> ControlFlow<()>> Observer for F {
    fn pass(&mut self, report: &PassReport) -> ControlFlow<()> {
        self(report)
    }
}

/// A run's result.
pub struct Run {
    pub accumulation: Accumulation,
    pub stats: Stats,
    pub stopped: Stopped,
    pub error: Option<ErrorEstimate>,
    pub predictions: Vec<(String, Prediction)>,
    /// A classic render's film, as rendered.
    single: Option<Film>,
}

impl Run {
    /// The image: the passes' average, or a classic render's pass.
    pub fn film(&self) -> Film {
        match &self.single {
            Some(film) => film.clone(),
            None => self.accumulation.average(),
        }
    }
}

/// Renders `plan` with `method` (its camera at `settings`' resolution).
/// A classic render shows its phases' progress on `progress`; a
/// progressive one reports each pass to `observers`, in order, after adding
/// it (a pass cut short by an interrupt is not added).
pub fn drive(
    scene: &Scene,
    settings: &Settings,
    method: &dyn RenderMethod,
    plan: Plan,
    progress: Mode,
    observers: &mut [&mut dyn Observer],
) -> Run {
    if !plan.progressive {
        let (film, stats) = render_pass(scene, settings, method, plan.first, progress, &mut Guide::default());
        let stopped = if interrupt::requested() { Stopped::Interrupted } else { Stopped::Passes };
        let (accumulation, error, predictions) = (plan.start, None, Vec::new());
        return Run { accumulation, stats, stopped, error, predictions, single: Some(film) };
    }
    let Plan { start: mut acc, first, budget, .. } = plan;
    let start = Instant::now();
    let model = method.method().bias(settings.alpha);
    let mut stats = Stats::default();
    let mut pass = first;
    let mut last_pass_time = Duration::ZERO;
    let mut guide = Guide::progressive(settings.adaptive);
    if guide.needs_pilot() && first > 0 {
        // The adaptive counts come from pass 0's pilot: a render that
        // does not start there renders pass 0 for them alone, so that
        // its passes take the counts of one process rendering them all.
        render_pass(scene, settings, method, 0, Mode::Quiet, &mut guide);
    }
    let mut error = None;
    let mut predictions = Vec::new();
    let stopped = loop {
        if interrupt::requested() {
            break Stopped::Interrupted;
        }
        let rendered = pass - first;
        if rendered > 0 {
            if budget.end.is_some_and(|end| pass >= end) {
                break Stopped::Passes;
            }
            if budget.seconds.is_some_and(|s| (start.elapsed() + last_pass_time).as_secs_f64() > s) {
                break Stopped::Time;
            }
            if let (Some(target), Some(_)) = (budget.target_error, &error) {
                let reached = |p: &Prediction| p.relative_rmse() < target;
                let preds: Vec<&Prediction> = match budget.windows.len() {
                    0 => predictions.iter().take(1).map(|(_, p)| p).collect(),
                    _ => predictions.iter().skip(1).map(|(_, p)| p).collect(),
                };
                if acc.passes.count() >= MIN_PASSES_FOR_TARGET && preds.into_iter().all(reached) {
                    break Stopped::TargetError;
                }
            }
        }
        let t = Instant::now();
        let (film, pass_stats) = render_pass(scene, settings, method, pass, Mode::Quiet, &mut guide);
        if interrupt::requested() {
            // The pass was cut short: not a pass of the image.
            break Stopped::Interrupted;
        }
        stats.absorb(pass_stats);
        acc.add_pass(pass, &film, model.shrink(pass)).expect("a pass is rendered once");
        pass += 1;
        last_pass_time = t.elapsed();
        error = ErrorEstimate::new(&acc, model);
        predictions = predict(error.as_ref(), &budget.windows);
        let average = acc.average();
        let report = PassReport {
            film: &average,
            accumulation: &acc,
            passes: acc.passes.count(),
            rendered: pass - first,
            elapsed: start.elapsed(),
            photons: stats.global_emitted + stats.caustic_emitted,
            r_caustic: stats.r_caustic,
            r_global: stats.r_global,
            k_caustic: stats.k_caustic,
            k_global: stats.k_global,
            error: error.as_ref(),
            predictions: predictions.clone(),
        };
        // Every observer sees every pass, whichever asks to stop.
        let mut stop = false;
        for o in observers.iter_mut() {
            stop |= o.pass(&report).is_break();
        }
        if stop {
            break Stopped::Caller;
        }
    };
    for o in observers.iter_mut() {
        o.finish();
    }
    Run { accumulation: acc, stats, stopped, error, predictions, single: None }
}

/// Renders passes `first`, `first + 1`, … into `acc` (empty for a new
/// render, a partial's sums to resume one) until `budget` says stop;
/// `on_pass` sees the running average after every pass and may stop the
/// render.
pub fn render_passes(
    scene: &Scene,
    settings: &Settings,
    acc: Accumulation,
    first: u32,
    budget: &Budget,
    mut on_pass: impl FnMut(&PassReport) -> ControlFlow<()>,
) -> Run {
    let method = settings.method.unit(settings);
    let plan = Plan::passes(acc, first, budget.clone());
    drive(scene, settings, method.as_ref(), plan, Mode::Quiet, &mut [&mut on_pass])
}

/// The whole image's predicted error, then each window's (nothing without
/// an estimate).
pub fn predict(error: Option<&ErrorEstimate>, windows: &[Window]) -> Vec<(String, Prediction)> {
    let Some(e) = error else { return Vec::new() };
    std::iter::once(("image".to_string(), e.predict(None)))
        .chain(windows.iter().map(|w| (w.name.clone(), e.predict(Some(w)))))
        .collect()
}

/// Progressive rendering from pass 0 until `budget` says stop: the
/// average image and the statistics.
pub fn render_progressive(
    scene: &Scene,
    settings: &Settings,
    budget: Budget,
    mut on_pass: impl FnMut(&PassReport),
) -> (Film, Stats) {
    let acc = Accumulation::new(settings.width, settings.height);
    let run = render_passes(scene, settings, acc, 0, &budget, |r| {
        on_pass(r);
        ControlFlow::Continue(())
    });
    (run.film(), run.stats)
}
