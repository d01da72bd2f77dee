//! Progressive rendering: independent passes, averaged. Each photon-mapping
//! pass has its own photons and narrower estimates than the pass before
//! ([`super::photon_stage::Estimates::progressive`]), so the average
//! converges to the true image.

use super::render_pass;
use crate::film::Film;
use crate::progress::Mode;
use crate::scene::Scene;
use crate::settings::Settings;
use crate::stats::Stats;
use glam::DVec3;
use std::time::{Duration, Instant};

/// When a progressive render stops.
#[derive(Clone, Copy, Debug)]
pub enum Budget {
    Passes(u32),
    /// Wall-clock seconds: no pass starts that the last pass's duration says
    /// would end past the budget (at least one pass always runs).
    Seconds(f64),
}

/// The state of a progressive render after a pass, for progress displays
/// and periodic output.
pub struct PassReport<'a> {
    pub film: &'a Film,
    pub passes: u32,
    pub elapsed: Duration,
    pub r_caustic: f32,
    pub r_global: f32,
    pub k_caustic: usize,
    pub k_global: usize,
}

/// Progressive rendering: independent passes, each with its own photons (or,
/// for path tracing, its own camera samples), averaged. Photon mapping's
/// estimates narrow from pass to pass (`Estimates::progressive`), so the
/// average converges to the true image. `on_pass` sees the running average
/// after every pass.
pub fn render_progressive(
    scene: &Scene,
    settings: &Settings,
    budget: Budget,
    mut on_pass: impl FnMut(&PassReport),
) -> (Film, Stats) {
    let start = Instant::now();
    let (w, h) = (settings.width, settings.height);
    let mut sum = vec![DVec3::ZERO; w as usize * h as usize];
    let mut stats = Stats::default();
    let mut pass = 0u32;
    let mut last_pass_time = Duration::ZERO;
    let mut rims = None;
    loop {
        let more = match budget {
            Budget::Passes(n) => pass < n.max(1),
            Budget::Seconds(s) => pass == 0 || (start.elapsed() + last_pass_time).as_secs_f64() <= s,
        };
        if !more {
            break;
        }
        let t = Instant::now();
        let (film, pass_stats) = render_pass(scene, settings, pass, Mode::Quiet, &mut rims);
        stats.absorb(pass_stats);
        for (acc, px) in sum.iter_mut().zip(&film.pixels) {
            *acc += px.as_dvec3();
        }
        pass += 1;
        last_pass_time = t.elapsed();
        let average = average_film(w, h, &sum, pass);
        on_pass(&PassReport {
            film: &average,
            passes: pass,
            elapsed: start.elapsed(),
            r_caustic: stats.r_caustic,
            r_global: stats.r_global,
            k_caustic: stats.k_caustic,
            k_global: stats.k_global,
        });
    }
    (average_film(w, h, &sum, pass), stats)
}

fn average_film(w: u32, h: u32, sum: &[DVec3], passes: u32) -> Film {
    Film { width: w, height: h, pixels: sum.iter().map(|s| (*s / passes.max(1) as f64).as_vec3()).collect() }
}
