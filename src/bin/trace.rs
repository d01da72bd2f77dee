//! `trace SCENE OUT [DEPTH]`: the CS475 Whitted ray tracer. Reads a scene
//! file (notes/scene-format.md), shades with the course's Phong formula,
//! follows mirror bounces to DEPTH, writes PNG/PPM (8-bit, clamped) or EXR.

use clap::Parser;
use photonmap::error::Error;
use photonmap::film::ToneMap;
use photonmap::math::Color;
use photonmap::memory::available_memory;
use photonmap::output::{check_writable, same_file, write_with, Extras};
use photonmap::progress::{Mode, Wait};
use photonmap::provenance::SceneId;
use photonmap::render::tracers::WhittedTracing;
use photonmap::render::{render_with, Method};
use photonmap::scene::Scene;
use photonmap::settings::Settings;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[path = "photonmap/count.rs"]
mod count;
use count::count;

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

fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| format!("'{s}' must be a whole number from 0 to {}", u64::MAX))
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
    let start = Instant::now();
    check_writable(&cli.out)?;
    if let Some(threads) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads as usize)
            .build_global()
            .map_err(|e| Error::Invalid(format!("--threads: {e}")))?;
    }
    let size = std::fs::metadata(&cli.scene).map_or(String::new(), |m| format!(" ({:.1} MB)", m.len() as f64 / 1e6));
    let wait = Wait::start(Mode::detect(cli.quiet), format!("trace: loading {}{size}", cli.scene.display()));
    let file = photonmap::scene::file::load(&cli.scene).map_err(|e| Error::Invalid(e.to_string()))?;
    let id =
        SceneId::from_files(&cli.scene, &file.meshes).map_err(|e| Error::Io { path: cli.scene.clone(), source: e })?;
    for input in &id.inputs {
        if same_file(&cli.out, input) {
            return Err(Error::Invalid(format!(
                "{}: the output is also an input of the scene; it would be overwritten (choose another name)",
                cli.out.display()
            )));
        }
    }
    let n = file.rays_per_pixel_edge;
    let mut scene = Scene::from_parts(file.parts);
    wait.finish();
    let load_time = start.elapsed();
    let (w, h) = (cli.width.unwrap_or(scene.camera.width), cli.height.unwrap_or(scene.camera.height));
    scene.camera = scene.camera.fit(w, h).map_err(|e| Error::Invalid(format!("{}: {e}", cli.scene.display())))?;
    let spp = cli.spp.unwrap_or(n * n);
    // The film (12 bytes a pixel) and its 8-bit copy must fit.
    let need = w as u64 * h as u64 * 16;
    if available_memory().is_some_and(|available| need > available) {
        return Err(Error::Invalid(format!(
            "{}: a {w} x {h} image needs about {:.1} GB; less memory is available",
            cli.scene.display(),
            need as f64 / 1e9
        )));
    }
    if scene.lights.is_empty() && scene.ambient == Color::ZERO {
        return Err(Error::Invalid(format!(
            "{}: the scene has no light (a [[lights]] entry, an emissive shape or ambient), so its image is black",
            cli.scene.display()
        )));
    }
    let t = Instant::now();
    let settings =
        Settings { method: Method::Whitted, width: w, height: h, spp, seed: cli.seed, ..Settings::default() };
    let tracer = WhittedTracing { max_depth: cli.depth };
    let (film, _) = render_with(&scene, &settings, &tracer, Mode::detect(cli.quiet));
    let render_time = t.elapsed();
    let attributes = [
        ("scene", id.name.clone()),
        ("scene_sha256", id.hash.clone()),
        ("integrator", Method::Whitted.name().to_string()),
        ("seed", cli.seed.to_string()),
        ("spp", spp.to_string()),
        ("depth", cli.depth.to_string()),
        ("wall_seconds", format!("{:.3}", start.elapsed().as_secs_f64())),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    let t = Instant::now();
    write_with(&cli.out, &film, ToneMap::Clamp, 1.0, &Extras { attributes, layers: Vec::new() })?;
    let write_time = t.elapsed();
    if !cli.quiet {
        let threads = rayon::current_num_threads();
        let threads = photonmap::stats::counted(threads as u64, "thread", "threads");
        eprintln!("trace: Whitted, {w} x {h}, {spp} spp, depth {}, {threads}", cli.depth);
        eprintln!(
            "  scene load   {:>8.3} s  {} primitives, {} lights",
            load_time.as_secs_f64(),
            scene.prim_count(),
            scene.lights.len()
        );
        eprintln!("  camera pass  {:>8.3} s", render_time.as_secs_f64());
        eprintln!("  write        {:>8.3} s  {}", write_time.as_secs_f64(), cli.out.display());
        eprintln!("  total        {:>8.3} s", start.elapsed().as_secs_f64());
    }
    Ok(())
}
