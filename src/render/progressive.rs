//! Progressive rendering: independent passes, averaged. Each photon-mapping
//! pass has its own photons and narrower estimates than the pass before
//! ([`super::photon_stage::Estimates::progressive`]), so the average
//! converges to the true image.
//!
//! A pass depends only on its index (random streams are keyed by pass, the
//! radius schedule is global), and the passes' sums are exact
//! ([`super::accumulation`]): any set of passes can be rendered anywhere,
//! in any order, and added into the same image as one process would make.

use super::accumulation::Accumulation;
use super::error_estimate::{ErrorEstimate, Prediction};
use super::render_pass;
use crate::film::Film;
use crate::interrupt;
use crate::metrics::Window;
use crate::progress::Mode;
use crate::scene::Scene;
use crate::settings::Settings;
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

/// A progressive render's result.
pub struct Run {
    pub accumulation: Accumulation,
    pub stats: Stats,
    pub stopped: Stopped,
    pub error: Option<ErrorEstimate>,
    pub predictions: Vec<(String, Prediction)>,
}

impl Run {
    pub fn film(&self) -> Film {
        self.accumulation.average()
    }
}

/// Renders passes `first`, `first + 1`, … into `start` (empty for a new
/// render, a partial's sums to resume one) until `budget` says stop;
/// `on_pass` sees the running average after every pass and may stop the
/// render.
pub fn render_passes(
    scene: &Scene,
    settings: &Settings,
    mut acc: Accumulation,
    first: u32,
    budget: &Budget,
    mut on_pass: impl FnMut(&PassReport) -> ControlFlow<()>,
) -> Run {
    let start = Instant::now();
    let model = settings.method.bias(settings.alpha);
    let unit = settings.method.unit(settings);
    let mut stats = Stats::default();
    let mut pass = first;
    let mut last_pass_time = Duration::ZERO;
    let mut rims = None;
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
        let (film, pass_stats) = render_pass(scene, settings, unit.as_ref(), pass, Mode::Quiet, &mut rims);
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
        let flow = on_pass(&PassReport {
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
        });
        if flow.is_break() {
            break Stopped::Caller;
        }
    };
    Run { accumulation: acc, stats, stopped, error, predictions }
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
