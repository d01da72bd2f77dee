//! `trace SCENE OUT [DEPTH]`: the CS475 Whitted ray tracer. Reads a scene
//! file (notes/scene-format.md), shades with the course's Phong formula,
//! follows mirror bounces to DEPTH, writes PNG/PPM (8-bit, clamped) or EXR.

use clap::Parser;
use photonmap::error::Error;
use photonmap::film::ToneMap;
use photonmap::integrator::whitted::Whitted;
use photonmap::memory::available_memory;
use photonmap::output::{check_writable, write};
use photonmap::scene::Scene;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Whitted ray tracer (CS475 A3): Phong shading, point and directional
/// lights with shadows, transformed spheres, recursive reflection, jittered
/// supersampling (the scene's rays_per_pixel_edge).
#[derive(Parser, Debug)]
#[command(version, after_help = "Example: trace scenes/whitted-spheres.toml spheres.png 5")]
struct Cli {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Output image: .png or .ppm (8-bit, colours clamped to [0, 1]) or
    /// .exr (linear float).
    out: PathBuf,
    /// Bounce depth: reflections stop after this many (0: none).
    #[arg(default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=1000))]
    depth: u32,
    /// Seed of the pixel jitter.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("trace: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), Error> {
    check_writable(&cli.out)?;
    let file = photonmap::scene::file::load(&cli.scene).map_err(|e| Error::Invalid(e.to_string()))?;
    let n = file.rays_per_pixel_edge;
    let scene = Scene::from_parts(file.parts);
    let (w, h) = (scene.camera.width, scene.camera.height);
    // The film (12 bytes a pixel) and its 8-bit copy must fit.
    let need = w as u64 * h as u64 * 16;
    if available_memory().is_some_and(|available| need > available) {
        return Err(Error::Invalid(format!(
            "{}: a {w} x {h} image needs about {:.1} GB; less memory is available",
            cli.scene.display(),
            need as f64 / 1e9
        )));
    }
    let start = Instant::now();
    let film = Whitted { scene: &scene, max_depth: cli.depth }.render(w, h, n, cli.seed);
    let elapsed = start.elapsed();
    write(&cli.out, &film, ToneMap::Clamp, 1.0)?;
    if !cli.quiet {
        eprintln!(
            "trace: {} x {}, {n} x {n} rays per pixel, depth {}, {} primitives, {} lights: {:.3} s",
            w,
            h,
            cli.depth,
            scene.prim_count(),
            scene.lights.len(),
            elapsed.as_secs_f64()
        );
    }
    Ok(())
}
