//! What a render says when it ends: the summary, the predicted error, and
//! its scores against a --reference.

use photonmap::error::Error;
use photonmap::metrics::compare;
use photonmap::render::summary::Summary;
use photonmap::settings::Settings;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// The summary, the predicted error and the reference's scores.
#[allow(clippy::too_many_arguments)]
pub fn finish(
    quiet: bool,
    settings: &Settings,
    stats: &photonmap::stats::Stats,
    load_time: Duration,
    write_time: Duration,
    start: Instant,
    files: &[PathBuf],
    film: &photonmap::film::Film,
    reference: Option<&photonmap::film::Film>,
    predictions: &[(String, photonmap::render::error_estimate::Prediction)],
) -> Result<(), Error> {
    if !quiet {
        let unit = settings.method.unit(settings);
        let summary = Summary {
            stats,
            settings,
            method: unit.as_ref(),
            threads: rayon::current_num_threads(),
            load_time,
            write_time,
            total_time: start.elapsed(),
            written: files,
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
            start.elapsed().as_secs_f64(),
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
