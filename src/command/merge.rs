//! `photonmap merge`: adds partial renders (passes rendered by separate
//! processes or machines) into the image one process would have made, bit
//! for bit, in any order.

use super::outputs::{write_outputs, Look, Outputs, Written};
use crate::error::Error;
use crate::metrics::Window;
use crate::output::partial::{merge, read_partial, Partial};
use crate::render::driver::predict;
use crate::render::error_estimate::ErrorEstimate;
use crate::render::Method;
use std::path::PathBuf;
use std::time::Instant;

/// A merge as the command line asks it.
pub struct Request {
    pub parts: Vec<PathBuf>,
    pub outputs: Outputs,
    /// Merge even where passes are missing between the parts' ranges.
    pub allow_gaps: bool,
    pub windows: Vec<Window>,
    pub look: Look,
    pub quiet: bool,
}

pub fn run(args: Request) -> Result<(), Error> {
    let start = Instant::now();
    let outputs = &args.outputs;
    if outputs.is_empty() {
        return Err(Error::Invalid("merge: no output given (-o OUT.exr or --partial PART.exr)".into()));
    }
    let windows = &args.windows;
    outputs.check_writable()?;
    let inputs: Vec<(&str, &std::path::Path)> = args.parts.iter().map(|p| ("partial merged", p.as_path())).collect();
    outputs.check_not_inputs(&inputs, None)?;
    let parts: Vec<(String, Partial)> =
        args.parts.iter().map(|p| Ok((p.display().to_string(), read_partial(p)?))).collect::<Result<_, Error>>()?;
    let merged = merge(&parts, args.allow_gaps)?;
    let m = &merged.manifest;
    for w in windows {
        if w.rows.1 > m.height || w.cols.1 > m.width {
            return Err(Error::Invalid(format!(
                "--window {}: reaches outside the {}x{} image",
                w.name, m.width, m.height
            )));
        }
    }
    let film = merged.accumulation.average();
    let model = Method::from_name(&m.method)
        .ok_or_else(|| Error::Invalid(format!("merge: the parts name an unknown method \"{}\"", m.method)))?
        .bias(m.alpha);
    let error = ErrorEstimate::new(&merged.accumulation, model);
    let photons: u64 = m.parts.iter().map(|p| p.photons).sum();
    let seconds: f64 = m.parts.iter().map(|p| p.seconds).sum();
    let attributes = vec![
        ("scene".to_string(), m.scene.clone()),
        ("scene_sha256".to_string(), m.scene_hash.clone()),
        ("integrator".to_string(), m.method.clone()),
        ("passes".to_string(), m.passes.clone()),
        ("photons_emitted".to_string(), photons.to_string()),
        ("wall_seconds".to_string(), format!("{seconds:.3}")),
        ("settings".to_string(), m.settings.clone()),
        ("merged_from".to_string(), args.parts.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")),
    ];
    let written = Written { film: &film, error: error.as_ref(), attributes };
    let files = write_outputs(outputs, &written, Some(&merged), args.look)?;
    if !args.quiet {
        eprintln!(
            "photonmap merge: {} parts, passes {} ({} in all), {}x{}",
            parts.len(),
            m.passes,
            merged.accumulation.passes.count(),
            m.width,
            m.height
        );
        eprintln!("  {:<40} {:>12} {:>14} {:>10}", "part", "passes", "photons", "seconds");
        for (name, p) in &parts {
            for part in &p.manifest.parts {
                eprintln!("  {:<40} {:>12} {:>14} {:>10.1}", name, part.passes, part.photons, part.seconds);
            }
        }
        eprintln!("  {:<40} {:>12} {:>14} {:>10.1}", "total", merged.accumulation.passes.count(), photons, seconds);
        for (name, p) in predict(error.as_ref(), windows) {
            eprintln!(
                "  error {name}: RMSE {:.5} ({:.2}% of mean; noise {:.5}, bias {:.5})",
                p.rmse,
                100.0 * p.relative_rmse(),
                p.noise_rmse,
                p.bias_rmse
            );
        }
        for f in &files {
            eprintln!("  wrote {}", f.display());
        }
        eprintln!("  total {:.3} s", start.elapsed().as_secs_f64());
    }
    Ok(())
}
