//! What a render says when it ends: the summary (every line within 100
//! columns), the predicted error, and its scores against a --reference.

use crate::error::Error;
use crate::film::Film;
use crate::metrics::compare;
use crate::render::error_estimate::Prediction;
use crate::render::settings::Settings;
use crate::render::RenderMethod;
use crate::stats::{counted, Stats};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// A render's summary.
pub struct Summary<'a> {
    pub stats: &'a Stats,
    pub settings: &'a Settings,
    /// The method rendered with: its own lines.
    pub method: &'a dyn RenderMethod,
    pub threads: usize,
    /// Reading the scene file and building the scene (its BVH).
    pub load_time: Duration,
    pub write_time: Duration,
    pub total_time: Duration,
    pub written: &'a [PathBuf],
}

impl Summary<'_> {
    pub fn lines(&self) -> Vec<String> {
        let s = self.stats;
        let st = self.settings;
        let own = self.method.summary(s);
        let secs = |d: Duration| d.as_secs_f64();
        let per_s = |n: u64, d: Duration| n as f64 / secs(d).max(1e-9) / 1e6;
        let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
        let (passes, threads) =
            (counted(s.passes as u64, "pass", "passes"), counted(self.threads as u64, "thread", "threads"));
        let title = self.method.method().title();
        let mut out = vec![format!("photonmap: {title}, {passes}, {threads}, {} x {}", st.width, st.height)];
        out.push(format!("  scene load   {:>8.3} s", secs(self.load_time)));
        out.extend(own.lines);
        out.push(format!(
            "  camera pass  {:>8.3} s  {:>7.2} M rays/s  ({} spp{}, {} shadow rays)",
            secs(s.camera_time),
            per_s(s.camera.rays, s.camera_time),
            st.spp,
            own.camera,
            st.shadow_rays
        ));
        if s.edge_pixels > 0 && s.edge_spp_max > s.edge_spp {
            out.push(format!(
                "               {} pixels on a light's rim took {} extra samples on average, up to {}",
                s.edge_pixels, s.edge_spp, s.edge_spp_max
            ));
        } else if s.edge_pixels > 0 {
            out.push(format!(
                "               {} pixels on a light's rim took {} extra samples",
                s.edge_pixels, s.edge_spp
            ));
        }
        if s.adaptive_pixels > 0 {
            let pixels = st.width as u64 * st.height as u64 * st.spp.max(1) as u64;
            out.push(format!(
                "               adaptive: {} pixels took more samples after the first pass ({:+.1}% samples a pass)",
                s.adaptive_pixels,
                100.0 * s.adaptive_samples as f64 / pixels.max(1) as f64
            ));
        }
        let c = &s.camera;
        if c.rims_too_costly > 0 {
            out.push(
                "               no light rims sought: a probe of the emitted part costs more rays than a whole sample here"
                    .to_string(),
            );
        }
        if c.caustic_estimates + c.caustic_reused > 0 {
            out.push(format!(
                "               {} caustic estimates, {} reused within a pixel ({:.0}%)",
                c.caustic_estimates,
                c.caustic_reused,
                pct(c.caustic_reused, c.caustic_estimates + c.caustic_reused)
            ));
        }
        if c.cache_rays > 0 {
            out.push(format!(
                "               {} rays to cache points at another level, {} hidden ({:.0}%)",
                c.cache_rays,
                c.cache_hidden,
                pct(c.cache_hidden, c.cache_rays)
            ));
        }
        let mut skipped = own.skipped;
        if c.shadow_rays_skipped > 0 {
            skipped.push(format!("{} shadow rays to lights facing away", c.shadow_rays_skipped));
        }
        for (i, what) in skipped.iter().enumerate() {
            out.push(format!("  {}  {what}", if i == 0 { "skipped:  " } else { "          " }));
        }
        out.push(format!("  write        {:>8.3} s", secs(self.write_time)));
        for path in self.written {
            out.push(format!("               {}", path.display()));
        }
        out.push(format!("  total        {:>8.3} s", secs(self.total_time)));
        out
    }
}

/// The times and files of a render's end.
pub struct Ending<'a> {
    /// Reading the scene file and building the scene.
    pub load_time: Duration,
    pub write_time: Duration,
    /// When the run started.
    pub start: Instant,
    pub files: &'a [PathBuf],
}

/// The summary, the predicted error and the reference's scores.
#[allow(clippy::too_many_arguments)]
pub fn finish(
    quiet: bool,
    settings: &Settings,
    method: &dyn RenderMethod,
    stats: &Stats,
    ending: &Ending,
    film: &Film,
    reference: Option<&Film>,
    predictions: &[(String, Prediction)],
) -> Result<(), Error> {
    if !quiet {
        let summary = Summary {
            stats,
            settings,
            method,
            threads: rayon::current_num_threads(),
            load_time: ending.load_time,
            write_time: ending.write_time,
            total_time: ending.start.elapsed(),
            written: ending.files,
        };
        for line in summary.lines() {
            eprintln!("{line}");
        }
        for (i, (name, p)) in predictions.iter().enumerate() {
            eprintln!(
                "  {}  {name}: RMSE {:.5} ({:.2}% of mean; noise {:.5}, bias {:.5}), relMSE {:.6}",
                if i == 0 { "error      " } else { "           " },
                p.rmse,
                100.0 * p.relative_rmse(),
                p.noise_rmse,
                p.bias_rmse,
                p.relmse
            );
        }
    }
    if stats.camera.nonfinite > 0 {
        let (pixel, estimator) = stats.camera.first_nonfinite().unwrap_or((0, "?"));
        eprintln!(
            "photonmap: warning: {} non-finite samples were dropped; first in the {estimator} estimate at pixel ({}, {})",
            stats.camera.nonfinite,
            pixel % settings.width as u64,
            pixel / settings.width as u64
        );
    }
    if let Some(reference) = reference {
        let m = compare(film, reference).ok_or_else(|| {
            Error::Invalid(format!(
                "--reference: a {}x{} image cannot be compared with a {}x{} reference",
                film.width, film.height, reference.width, reference.height
            ))
        })?;
        println!(
            "{{\"seconds\": {:.3}, \"rmse\": {:.6}, \"relmse\": {:.6}, \"caustic_rmse\": {:.6}, \"mean_x\": {:.6}, \"mean_r\": {:.6}, \"caustic_mean_x\": {:.6}, \"caustic_mean_r\": {:.6}, \"nan_count\": {}}}",
            ending.start.elapsed().as_secs_f64(),
            m.rmse,
            m.relmse,
            m.caustic_rmse,
            m.mean_x,
            m.mean_r,
            m.caustic_mean_x,
            m.caustic_mean_r,
            m.nan_count
        );
    }
    Ok(())
}
