//! Rendering: the default command. Parses and checks the options, loads
//! the scene, renders (classic or progressive), writes, summarises.

use clap::ValueEnum;
use photonmap::error::Error;
use photonmap::film::ToneMap;
use photonmap::memory::available_memory;
use photonmap::metrics::compare;
use photonmap::output::{check_writable, read_exr, write};
use photonmap::progress::{Mode, PassDisplay};
use photonmap::render::{render, render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings, DEFAULT};
use photonmap::stats::Summary;
use std::path::PathBuf;
use std::time::Instant;

/// The estimator (`--integrator`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum IntegratorArg {
    /// Photon mapping: direct light, caustic map, final gathering.
    Photon,
    /// Path tracing with next-event estimation (unbiased, the reference).
    Path,
}

/// How 8-bit outputs are made from radiance (`--tonemap`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ToneMapArg {
    /// Exposure from the image (its log-average luminance to middle grey),
    /// then the sRGB curve.
    Display,
    /// v * 255.99 / i_max, i_max the largest channel value (the course's).
    Linear,
    /// sqrt(v) * 255.99 / sqrt(i_max): for scenes with bright spots.
    Sqrt,
    /// v * 255.99 clamped: 1.0 is white (the Whitted course's colours).
    Clamp,
}

/// Rendering (the default command).
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Render this scene file (TOML, notes/scene-format.md) instead of the
    /// built-in room; its camera, resolution and rays_per_pixel_edge are the
    /// defaults of --width, --height and --spp.
    #[arg(long, value_name = "SCENE.toml", conflicts_with = "eye")]
    scene: Option<PathBuf>,
    /// Output images; the extension picks the format: .exr (linear float
    /// radiance), .png or .ppm (8-bit, tone-mapped).
    #[arg(value_name = "OUT")]
    outputs: Vec<PathBuf>,
    /// More output images (repeatable), as for OUT.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    more_outputs: Vec<PathBuf>,
    /// Estimator: photon (photon mapping) or path (path tracing with
    /// next-event estimation, unbiased: the reference).
    #[arg(long, value_enum, default_value_t = IntegratorArg::Photon)]
    integrator: IntegratorArg,
    /// Progressive rendering: this many independent passes, averaged; photon
    /// mapping narrows its estimates (fewer photons each, smaller radius
    /// caps) from pass to pass so the image converges to the true one.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000_000), conflicts_with = "time")]
    passes: Option<u32>,
    /// Progressive rendering until this many seconds have passed (no pass
    /// starts that would end later; at least one runs). The output is
    /// rewritten every few passes, so stopping early keeps a valid image.
    #[arg(long, value_parser = parse_seconds)]
    time: Option<f64>,
    /// How fast progressive photon mapping narrows its estimates (Knaus &
    /// Zwicker's alpha): pass i uses k and squared radius caps times
    /// prod_{j<i} (j + alpha - 1) / j.
    #[arg(long, default_value_t = DEFAULT.alpha, value_parser = parse_alpha)]
    alpha: f32,
    /// Photons emitted for the global map, per pass (1e6, 2.5e5 and 1000000 all work).
    #[arg(long, default_value = "1e6", value_parser = parse_count)]
    photons: u64,
    /// Photons emitted towards mirrors and glass for the caustic map
    /// [default: the same as --photons].
    #[arg(long, value_parser = parse_count)]
    caustic_photons: Option<u64>,
    /// Jittered camera samples per pixel (stratified when a square)
    /// [default: 4, or rays_per_pixel_edge squared from a scene file].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    spp: Option<u32>,
    /// Seed of every random stream: the same seed gives the same image on any
    /// number of threads.
    #[arg(long, default_value_t = DEFAULT.seed)]
    seed: u64,
    /// Eye position: 1 = (-2,0,0), 53 degree view; 2 = (-1,0,0), 90 degrees.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    eye: Option<u8>,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// Image width in pixels; the image plane stays the camera's [default:
    /// 800, or the scene file's].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    width: Option<u32>,
    /// Image height in pixels [default: 800, or the scene file's].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    height: Option<u32>,
    /// Nearest photons per global-map irradiance estimate (at least 2: the
    /// estimate counts those strictly inside the k-th photon's distance).
    #[arg(long, default_value_t = DEFAULT.k_global as u32, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    k: u32,
    /// Nearest photons per caustic estimate (at least 2).
    #[arg(long, default_value_t = DEFAULT.k_caustic as u32, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    k_caustic: u32,
    /// Largest search radius of a global-map estimate, in scene units
    /// [default: 5% of the scene's diagonal].
    #[arg(long, value_parser = parse_radius)]
    max_radius: Option<f32>,
    /// Largest search radius of a caustic estimate [default: 1% of the diagonal].
    #[arg(long, value_parser = parse_radius)]
    caustic_radius: Option<f32>,
    /// Final-gather rays per diffuse camera hit (0: no indirect light).
    #[arg(long, default_value_t = DEFAULT.gather_rays, value_parser = clap::value_parser!(u32).range(0..=65_536))]
    gather_rays: u32,
    /// Shadow rays per light per diffuse camera hit.
    #[arg(long, default_value_t = DEFAULT.shadow_rays, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    shadow_rays: u32,
    /// Irradiance is precomputed at every N-th stored global photon, and
    /// final-gather rays read the nearest precomputed value [default: k / 6,
    /// 16 at k = 100, following k down in progressive passes].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    cache_stride: Option<u32>,
    /// A pixel's later camera samples reuse its last caustic estimate where
    /// they land on the same surface within this fraction of that
    /// estimate's radius (0 to 1; 0: every sample makes its own).
    #[arg(long, default_value_t = DEFAULT.caustic_reuse, value_parser = parse_fraction)]
    caustic_reuse: f32,
    /// Samples of the light seen in pixels on the rim of a light's image
    /// (directly or in mirrors and glass; 0: no extra samples).
    #[arg(long, default_value_t = DEFAULT.edge_spp, value_parser = clap::value_parser!(u32).range(0..=1_000_000))]
    edge_spp: u32,
    /// Do everything even where the scene cannot use it (photon maps, shadow
    /// rays towards lights facing away): for checking that the skips change
    /// nothing.
    #[arg(long)]
    no_skip: bool,
    /// How 8-bit outputs (.png, .ppm) are made from radiance: display (an
    /// exposure from the image, then sRGB), or the course's linear (255.99 /
    /// i_max) and sqrt mappings, or clamp (1.0 is white). EXR is always
    /// linear radiance.
    #[arg(long, value_enum, default_value_t = ToneMapArg::Display)]
    tonemap: ToneMapArg,
    /// Brightness factor of 8-bit outputs, applied on top of the tone map
    /// (values past white clip).
    #[arg(long, default_value_t = 1.0, value_parser = parse_exposure)]
    exposure: f32,
    /// Score the render against a reference EXR of the default scene (the
    /// metric of shared/refs/metrics.py) and print the numbers.
    #[arg(long, value_name = "REF.exr")]
    reference: Option<PathBuf>,
    /// No progress bars and no summary.
    #[arg(short, long)]
    quiet: bool,
}

/// A photon count: an integer written plainly or in e-notation.
fn parse_count(s: &str) -> Result<u64, String> {
    let v: f64 = s.trim().parse().map_err(|_| format!("'{s}' is not a number (try 1e6 or 250000)"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("'{s}' must be zero or a positive count"));
    }
    if v.fract() != 0.0 {
        return Err(format!("'{s}' is not a whole number of photons"));
    }
    // Photon indices are 32-bit in the kd-tree; beyond this the maps would
    // not fit in memory on any machine this runs on anyway.
    const MAX: f64 = 1e9;
    if v > MAX {
        return Err(format!("'{s}' is more than the 1e9 photons a map can hold"));
    }
    Ok(v as u64)
}

fn parse_radius(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive distance")),
    }
}

fn parse_fraction(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' must be a number from 0 to 1")),
    }
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v < 1e7 => Ok(v),
        _ => Err(format!("'{s}' must be a positive number of seconds")),
    }
}

fn parse_alpha(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("'{s}' must lie strictly between 0 and 1")),
    }
}

fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive factor")),
    }
}

pub fn run(cli: RenderArgs) -> Result<(), Error> {
    let start = Instant::now();
    let outputs: Vec<PathBuf> = cli.outputs.iter().chain(&cli.more_outputs).cloned().collect();
    if outputs.is_empty() {
        return Err(Error::Invalid("no output file given (e.g. photonmap out.exr)".into()));
    }
    // Every output path is checked before any time is spent rendering.
    for path in &outputs {
        check_writable(path)?;
    }
    let reference = cli.reference.as_deref().map(read_exr).transpose()?;
    if let Some(threads) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads as usize)
            .build_global()
            .map_err(|e| Error::Invalid(format!("--threads: {e}")))?;
    }
    let loading = Instant::now();
    let (scene, file_spp) = match &cli.scene {
        None => (Scene::tncg15(if cli.eye == Some(2) { Eye::Two } else { Eye::One }), 4),
        Some(path) => {
            let file = photonmap::scene::file::load(path).map_err(|e| Error::Invalid(e.to_string()))?;
            if !file.not_physical.is_empty() {
                let all: Vec<String> = file.not_physical.iter().map(|e| e.to_string()).collect();
                return Err(Error::Invalid(format!(
                    "{}\n(the `trace` program renders this scene; photonmap cannot honour these)",
                    all.join("\n")
                )));
            }
            let n = file.rays_per_pixel_edge;
            (Scene::from_parts(file.parts), n * n)
        }
    };
    let load_time = loading.elapsed();
    let width = cli.width.unwrap_or(scene.camera.width);
    let height = cli.height.unwrap_or(scene.camera.height);
    let tonemap = match cli.tonemap {
        ToneMapArg::Display => ToneMap::Display,
        ToneMapArg::Linear => ToneMap::Linear,
        ToneMapArg::Sqrt => ToneMap::Sqrt,
        ToneMapArg::Clamp => ToneMap::Clamp,
    };
    let settings = Settings {
        method: match cli.integrator {
            IntegratorArg::Photon => Method::Photon,
            IntegratorArg::Path => Method::Path,
        },
        alpha: cli.alpha,
        photons: cli.photons,
        caustic_photons: cli.caustic_photons.unwrap_or(cli.photons),
        spp: cli.spp.unwrap_or(file_spp),
        seed: cli.seed,
        width,
        height,
        k_global: cli.k as usize,
        k_caustic: cli.k_caustic as usize,
        r_global: cli.max_radius,
        r_caustic: cli.caustic_radius,
        gather_rays: cli.gather_rays,
        shadow_rays: cli.shadow_rays,
        edge_spp: cli.edge_spp,
        cache_stride: cli.cache_stride.map(|n| n as usize),
        caustic_reuse: cli.caustic_reuse,
        skip: !cli.no_skip,
    };
    // Refuse before allocating: a map that cannot fit would abort the
    // process half-way, after minutes of work.
    if let Some(available) = available_memory() {
        let need = settings.estimated_peak_bytes();
        if need > available {
            return Err(Error::Invalid(format!(
                "--photons {} / --caustic-photons {} at {}x{} need about {:.1} GB; {:.1} GB of memory is available",
                settings.photons,
                settings.caustic_photons,
                settings.width,
                settings.height,
                need as f64 / 1e9,
                available as f64 / 1e9
            )));
        }
    }
    if settings.photons == 0 && !cli.quiet {
        eprintln!("photonmap: warning: --photons 0: no global map, so indirect light is missing");
    }
    if settings.caustic_photons == 0 && !cli.quiet {
        eprintln!("photonmap: warning: no caustic photons: caustics are missing");
    }
    let mode = Mode::detect(cli.quiet);
    let budget = match (cli.passes, cli.time) {
        (Some(n), _) => Some(Budget::Passes(n)),
        (None, Some(s)) => Some(Budget::Seconds(s)),
        (None, None) => None,
    };
    let (film, stats) = match budget {
        None => render(&scene, &settings, mode),
        Some(budget) => {
            let mut last_write = Instant::now();
            let mut write_error = None;
            let display = PassDisplay::new(mode, budget);
            let result = render_progressive(&scene, &settings, budget, |report| {
                display.update(report);
                // Rewrite the outputs now and then (atomically), so a user who
                // stops the run keeps an image of every pass so far.
                if write_error.is_none() && last_write.elapsed().as_secs_f64() > 10.0 {
                    for path in &outputs {
                        if let Err(e) = write(path, report.film, tonemap, cli.exposure) {
                            write_error = Some(e);
                        }
                    }
                    last_write = Instant::now();
                }
            });
            display.finish();
            if let Some(e) = write_error {
                return Err(e);
            }
            result
        }
    };
    let t = Instant::now();
    for path in &outputs {
        write(path, &film, tonemap, cli.exposure)?;
    }
    let write_time = t.elapsed();
    if !cli.quiet {
        let summary = Summary {
            stats: &stats,
            settings: &settings,
            threads: rayon::current_num_threads(),
            load_time,
            write_time,
            total_time: start.elapsed(),
            written: &outputs,
        };
        for line in summary.lines() {
            eprintln!("{line}");
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
        let m = compare(&film, &reference).ok_or_else(|| {
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
