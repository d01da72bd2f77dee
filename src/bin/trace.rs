//! `trace SCENE OUT [DEPTH]`: the CS475 Whitted ray tracer's flags, for
//! `photonmap::command::trace`. It reads a scene file
//! (notes/scene-format.md), shades with the course's Phong formula,
//! follows mirror bounces to DEPTH, writes PNG/PPM (8-bit, clamped) or EXR.

use clap::Parser;
use photonmap::command::trace;
use photonmap::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;

#[path = "photonmap/count.rs"]
mod count;
use count::{count, parse_seed};

/// Whitted ray tracer (CS475 A3): Phong shading, point and directional
/// lights with shadows, transformed spheres, recursive reflection, jittered
/// supersampling (the scene's rays_per_pixel_edge).
#[derive(Parser, Debug)]
#[command(version, after_help = "Example: trace scenes/whitted-spheres.toml spheres.png 5")]
struct Cli {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Output image: .png or .ppm (8-bit, colours clamped to [0, 1]) or
    /// .exr (linear float, with how it was made in its header).
    out: PathBuf,
    /// Bounce depth: reflections stop after this many (0: none).
    #[arg(default_value_t = 5, value_parser = count(0, 1000))]
    depth: u32,
    /// Image width in pixels [default: the scene file's]. A size of another
    /// shape than the camera's widens a look-at camera's view; a
    /// four-corner camera's plane must have the image's shape.
    #[arg(long, value_parser = count(1, 65_536))]
    width: Option<u32>,
    /// Image height in pixels [default: the scene file's].
    #[arg(long, value_parser = count(1, 65_536))]
    height: Option<u32>,
    /// Jittered samples per pixel (stratified when a square) [default:
    /// rays_per_pixel_edge squared from the scene file].
    #[arg(long, value_parser = count(1, 1_000_000))]
    spp: Option<u32>,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = count(1, 4096))]
    threads: Option<u32>,
    /// Seed of the pixel jitter.
    #[arg(long, default_value_t = 1, value_parser = parse_seed)]
    seed: u64,
    /// No progress bar and no summary.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    // Ctrl-C, SIGTERM or SIGHUP (the ctrlc crate's `termination` feature)
    // stops at once, and leaves no half-written file behind.
    let _ = ctrlc::set_handler(|| {
        photonmap::output::remove_temporaries();
        std::process::exit(130);
    });
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("trace: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), Error> {
    if let Some(threads) = cli.threads {
        photonmap::command::checks::use_threads(threads, false)?;
    }
    trace::run(trace::Request {
        scene: cli.scene,
        out: cli.out,
        depth: cli.depth,
        width: cli.width,
        height: cli.height,
        spp: cli.spp,
        seed: cli.seed,
        quiet: cli.quiet,
    })
}
