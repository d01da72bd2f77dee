//! `photonmap compare TEST.exr REF.exr`: the flags of
//! `photonmap::command::compare`.

use crate::args::{parse_difference, parse_windows};
use photonmap::command::compare::{self, Request};
use photonmap::error::Error;
use std::io::Write;
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
    #[arg(long, value_name = "D", value_parser = parse_difference)]
    diff_scale: Option<f32>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<(), Error> {
    let request = Request {
        windows: parse_windows(&args.windows).map_err(Error::Invalid)?,
        test: args.test,
        reference: args.reference,
        variance: args.variance,
        fail_map: args.fail_map,
        diff: args.diff,
        diff_scale: args.diff_scale,
        json: args.json,
    };
    if !args.mitsuba_test {
        return compare::run(&request);
    }
    let code = compare::mitsuba_status(&request);
    let _ = std::io::stdout().flush();
    std::process::exit(code.into())
}
