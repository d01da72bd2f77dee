//! `photonmap compare TEST.exr REF.exr`: a render's error against a
//! reference, with the metric of `photonmap::metrics`; with
//! `--mitsuba-test` and the reference's variance, Mitsuba 3's acceptance
//! test instead (`mitsuba.rs`).

mod mitsuba;

use photonmap::error::Error;
use photonmap::metrics::{compare_images, diff_rgb8, Comparison, Region, Window};
use photonmap::output::{check_writable, read_exr, same_file, write_rgb8_image};
use std::path::PathBuf;

/// Scores TEST against REF: RMSE, relMSE, means and the test's relative
/// bias, for the whole image and each window; the count of speckle pixels;
/// optionally a signed difference picture. TEST is reduced to REF's size
/// by averaging blocks when REF is an integer factor smaller.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples: photonmap compare out.exr ref.exr --window caustic=173:193,126:157 --diff diff.png\n          photonmap compare --mitsuba-test out.exr scene_ref_rgb.exr scene_ref_rgb_var.exr --fail-map failing.png"
)]
pub struct Args {
    /// The image to score (EXR, linear radiance).
    test: PathBuf,
    /// The reference (EXR), the test's size or an integer factor smaller
    /// (with --mitsuba-test: the test's size).
    reference: PathBuf,
    /// With --mitsuba-test: the reference's per-pixel variance (EXR).
    #[arg(requires = "mitsuba_test", value_name = "VARIANCE")]
    variance: Option<PathBuf>,
    /// Mitsuba 3's render-test acceptance (its tests/test_renders.py):
    /// images in XYZ, variance floored at 1e-4, z = |TEST - REF| *
    /// sqrt(spp / VARIANCE) with spp = 2,000,000 / pixels, a pixel channel
    /// passing when its two-sided p-value exceeds the Sidak level 1 -
    /// 0.99^(1/pixels), accepted when 99.75% pass and TEST is finite. Exit
    /// status: 0 accepted, 1 rejected, 2 the test could not be run.
    #[arg(long, requires = "variance", conflicts_with_all = ["windows", "diff", "diff_scale"])]
    mitsuba_test: bool,
    /// With --mitsuba-test: write a picture of the failing pixels (red) over
    /// the dimmed test image (.png or .ppm).
    #[arg(long, value_name = "OUT.png", requires = "mitsuba_test")]
    fail_map: Option<PathBuf>,
    /// A rectangle of reference pixels scored on its own, as
    /// [NAME=]ROW0:ROW1,COL0:COL1 (half-open, row 0 at the top); repeatable.
    #[arg(long = "window", value_name = "[NAME=]R0:R1,C0:C1")]
    windows: Vec<String>,
    /// Write a signed false-colour picture of TEST - REF (at REF's size):
    /// red where the test is brighter, blue where darker, black where equal.
    #[arg(long, value_name = "OUT.png")]
    diff: Option<PathBuf>,
    /// The difference that the picture shows at full intensity [default:
    /// the 99th percentile of the absolute differences].
    #[arg(long, value_name = "D", value_parser = parse_scale)]
    diff_scale: Option<f32>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

fn parse_scale(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive difference")),
    }
}

pub fn run(args: Args) -> Result<(), Error> {
    if args.mitsuba_test {
        mitsuba::run(&args);
    }
    let windows: Vec<Window> = args
        .windows
        .iter()
        .enumerate()
        .map(|(i, w)| Window::parse(w, i))
        .collect::<Result<_, _>>()
        .map_err(|e| Error::Invalid(format!("--window: {e}")))?;
    if let Some(diff) = &args.diff {
        check_writable(diff)?;
        for input in [&args.test, &args.reference] {
            if same_file(diff, input) {
                return Err(Error::Invalid(format!("--diff {}: that is an input of the comparison", diff.display())));
            }
        }
    }
    let test = read_exr(&args.test)?;
    let reference = read_exr(&args.reference)?;
    let c = compare_images(&test, &reference, &windows)
        .map_err(|e| Error::Invalid(format!("{} against {}: {e}", args.test.display(), args.reference.display())))?;
    let diff_scale = match &args.diff {
        Some(path) => {
            let reduced = photonmap::metrics::box_down(&test, c.factor);
            let (rgb, scale) = diff_rgb8(&reduced, &reference, args.diff_scale);
            write_rgb8_image(path, reference.width, reference.height, rgb)?;
            Some(scale)
        }
        None => None,
    };
    if args.json {
        println!("{}", json(&c, diff_scale));
    } else {
        print!("{}", table(&c, &args, diff_scale));
    }
    Ok(())
}

fn region_json(r: &Region) -> serde_json::Value {
    serde_json::json!({
        "rmse": r.rmse,
        "relmse": r.relmse,
        "mean_test": r.mean_test,
        "mean_ref": r.mean_ref,
        "bias": r.relative_bias(),
        "pixels": r.pixels,
    })
}

pub fn json(c: &Comparison, diff_scale: Option<f32>) -> serde_json::Value {
    let windows: Vec<serde_json::Value> = c
        .windows
        .iter()
        .map(|(w, r)| {
            let mut v = region_json(r);
            v["name"] = w.name.clone().into();
            v["rows"] = serde_json::json!([w.rows.0, w.rows.1]);
            v["cols"] = serde_json::json!([w.cols.0, w.cols.1]);
            v
        })
        .collect();
    let mut v = serde_json::json!({
        "factor": c.factor,
        "whole": region_json(&c.whole),
        "windows": windows,
        "nan_count": c.nan_count,
        "speckles": c.speckles,
    });
    if let Some(s) = diff_scale {
        v["diff_scale"] = s.into();
    }
    v
}

fn table(c: &Comparison, args: &Args, diff_scale: Option<f32>) -> String {
    let mut out = String::new();
    let reduced = if c.factor > 1 { format!(" (test reduced {0}x{0})", c.factor) } else { String::new() };
    out += &format!("{} against {}{reduced}\n", args.test.display(), args.reference.display());
    out +=
        &format!("{:<12} {:>10} {:>10} {:>10} {:>10} {:>8}\n", "region", "rmse", "relmse", "mean", "ref mean", "bias");
    let row = |name: &str, r: &Region| {
        let bias = match r.relative_bias() {
            Some(b) => format!("{:>+7.2}%", 100.0 * b),
            None => "undefined".into(),
        };
        format!(
            "{:<12} {:>10.6} {:>10.6} {:>10.6} {:>10.6} {bias:>8}\n",
            name, r.rmse, r.relmse, r.mean_test, r.mean_ref
        )
    };
    out += &row("whole", &c.whole);
    for (w, r) in &c.windows {
        out += &row(&w.name, r);
    }
    if std::iter::once(&c.whole).chain(c.windows.iter().map(|(_, r)| r)).any(|r| r.relative_bias().is_none()) {
        out += "bias undefined: the reference's mean is 0 there, so no relative figure means anything\n";
    }
    let scored = if c.nan_count > 0 { " (scored as 0)" } else { "" };
    out += &format!("speckles: {} pixels; non-finite values in the test: {}{scored}\n", c.speckles, c.nan_count);
    if let (Some(path), Some(s)) = (&args.diff, diff_scale) {
        out += &format!("difference picture: {} (full intensity at {s:.4})\n", path.display());
    }
    out
}
