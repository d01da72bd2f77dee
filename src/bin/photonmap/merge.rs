//! `photonmap merge PARTS... -o OUT`: the flags of
//! `photonmap::command::merge`.

use crate::args::{parse_exposure, parse_windows, Named};
use photonmap::command::merge;
use photonmap::command::outputs::{Look, Outputs};
use photonmap::error::Error;
use photonmap::film::ToneMap;
use std::path::PathBuf;

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
    /// How 8-bit outputs are made from radiance, as for rendering.
    #[arg(long, value_enum, default_value_t = Named(ToneMap::Display))]
    tonemap: Named<ToneMap>,
    /// Brightness factor of 8-bit outputs, as for rendering.
    #[arg(long, default_value_t = 1.0, value_parser = parse_exposure)]
    exposure: f32,
    /// No summary.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: Args) -> Result<(), Error> {
    merge::run(merge::Request {
        parts: args.parts,
        outputs: Outputs { images: args.outputs, partial: args.partial, error_map: args.error_map },
        allow_gaps: args.allow_gaps,
        windows: parse_windows(&args.windows).map_err(Error::Invalid)?,
        look: Look { tonemap: args.tonemap.0, exposure: args.exposure },
        quiet: args.quiet,
    })
}
