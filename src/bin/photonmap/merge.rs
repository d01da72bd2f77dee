//! `photonmap merge PARTS... -o OUT`: adds partial renders (passes rendered
//! by separate processes or machines) into the image one process would
//! have made, bit for bit, in any order.

use crate::args::{parse_exposure, parse_windows, ToneMapArg};
use crate::outputs::Outputs;
use crate::write::{write_outputs, Written};
use photonmap::error::Error;
use photonmap::output::partial::{merge, read_partial, Partial};
use photonmap::render::error_estimate::ErrorEstimate;
use photonmap::render::progressive::predict;
use photonmap::render::Method;
use std::path::PathBuf;
use std::time::Instant;

/// Adds partial renders (written with --partial) into one image: the same
/// bytes as rendering their passes in one process, whatever the split and
/// the order. Refuses parts of another scene or settings, passes given
/// twice, and (unless --allow-gaps) missing passes.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example: photonmap merge part-*.exr -o out.exr -o out.png --partial all.exr")]
pub struct Args {
    /// The partial renders.
    #[arg(required = true, value_name = "PART.exr")]
    parts: Vec<PathBuf>,
    /// Output images (.exr, .png, .ppm); repeatable.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    outputs: Vec<PathBuf>,
    /// Also write the merged sums as a partial (to merge further, or to
    /// resume from).
    #[arg(long, value_name = "PART.exr")]
    partial: Option<PathBuf>,
    /// Merge even where passes are missing between the parts' ranges.
    #[arg(long)]
    allow_gaps: bool,
    /// Write a heat map of the per-pixel predicted error.
    #[arg(long, value_name = "FILE.png")]
    error_map: Option<PathBuf>,
    /// A rectangle whose predicted error is reported, as for rendering.
    #[arg(long = "window", value_name = "[NAME=]R0:R1,C0:C1")]
    windows: Vec<String>,
    #[arg(long, value_enum, default_value_t = ToneMapArg::Display)]
    tonemap: ToneMapArg,
    #[arg(long, default_value_t = 1.0, value_parser = parse_exposure)]
    exposure: f32,
    /// No summary.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: Args) -> Result<(), Error> {
    let start = Instant::now();
    let outputs =
        Outputs { images: args.outputs.clone(), partial: args.partial.clone(), error_map: args.error_map.clone() };
    if outputs.is_empty() {
        return Err(Error::Invalid("merge: no output given (-o OUT.exr or --partial PART.exr)".into()));
    }
    let windows = parse_windows(&args.windows).map_err(Error::Invalid)?;
    outputs.check_writable()?;
    let inputs: Vec<(&str, &std::path::Path)> = args.parts.iter().map(|p| ("partial merged", p.as_path())).collect();
    outputs.check_not_inputs(&inputs, None)?;
    let parts: Vec<(String, Partial)> =
        args.parts.iter().map(|p| Ok((p.display().to_string(), read_partial(p)?))).collect::<Result<_, Error>>()?;
    let merged = merge(&parts, args.allow_gaps)?;
    let m = &merged.manifest;
    for w in &windows {
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
    let files = write_outputs(&outputs, &written, Some(&merged), args.tonemap.tonemap(), args.exposure)?;
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
        for (name, p) in predict(error.as_ref(), &windows) {
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
