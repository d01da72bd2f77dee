//! Rendering: the default command. Parses and checks the options and every
//! output, loads the scene, renders (classic, progressive, a range of
//! passes, or on from a partial), writes, summarises.

use crate::args::*;
use crate::checks::{path_tracer_sees, reference_shows, threads_within_cores, TargetWatch, WEEK};
use crate::count::count;
use crate::outputs::Outputs;
use crate::summary::finish;
use crate::write::{provenance, write_outputs, Written};
use photonmap::display::Tev;
use photonmap::error::Error;
use photonmap::interrupt;
use photonmap::memory::available_memory;
use photonmap::metrics::{reduction_factor, Window};
use photonmap::output::partial::{read_partial, Manifest, Part, Partial};
use photonmap::output::read_exr;
use photonmap::progress::{Mode, PassDisplay, Wait};
use photonmap::provenance::{settings_key, SceneId};
use photonmap::render::accumulation::{parse_range, Accumulation};
use photonmap::render::{render, render_passes, Budget, Stopped};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings, DEFAULT, PROGRESSIVE_PHOTONS, PROGRESSIVE_SPP};
use photonmap::stats::counted;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

/// Outputs of a progressive render are rewritten this often, so a run
/// that dies keeps an image (and a partial) of its passes so far.
const REWRITE_SECONDS: f64 = 10.0;

/// Rendering (the default command).
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Render this scene file instead of the built-in room: photonmap's TOML
    /// (notes/scene-format.md) or Mitsuba 3's XML (.xml, notes/mitsuba.md);
    /// its camera, resolution and samples per pixel are the defaults of
    /// --width, --height and --spp.
    #[arg(long, value_name = "SCENE.toml|SCENE.xml", conflicts_with = "eye")]
    scene: Option<PathBuf>,
    /// Set a Mitsuba scene's parameter $NAME, as Mitsuba's -D does
    /// (repeatable; wins over the file's <default>).
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define, requires = "scene")]
    defines: Vec<(String, String)>,
    /// Render a Mitsuba scene even where a BSDF or emitter is not supported:
    /// a grey diffuse BSDF stands in, an emitter is left out; each is listed
    /// on stderr and in the EXR's header.
    #[arg(long, requires = "scene")]
    substitute: bool,
    /// Output images; the extension picks the format: .exr (linear float
    /// radiance, with how it was made in its header, and for progressive
    /// renders the error estimate's layers), .png or .ppm (8-bit,
    /// tone-mapped).
    #[arg(value_name = "OUT")]
    outputs: Vec<PathBuf>,
    /// More output images (repeatable), as for OUT.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    more_outputs: Vec<PathBuf>,
    /// Estimator: photon (photon mapping) or path (path tracing with
    /// next-event estimation, unbiased: the reference). Default: photon;
    /// path for a Mitsuba scene whose integrator stops paths at 3 or more
    /// vertices (max_depth), which photon mapping cannot do.
    #[arg(long, value_enum)]
    integrator: Option<MethodArg>,
    /// Progressive rendering: passes 0 to N-1, averaged (with --resume:
    /// until the image holds N passes). Photon mapping narrows its
    /// estimates from pass to pass so the image converges to the true one.
    #[arg(long, value_parser = count(1, 10_000_000))]
    passes: Option<u32>,
    /// Progressive rendering for this many seconds (no pass starts that
    /// would end later; at least one runs). Outputs are rewritten every 10
    /// s, so stopping early keeps a valid image. With --passes or
    /// --target-error, a cap.
    #[arg(long, value_parser = parse_seconds)]
    time: Option<f64>,
    /// Progressive rendering until the predicted relative RMSE (of every
    /// --window, or of the whole image) is below this (0.02: 2%); checked
    /// from the fourth pass on. --time caps it, else a week (a prediction
    /// beyond the cap is said).
    #[arg(long, value_name = "E", value_parser = parse_target)]
    target_error: Option<f64>,
    /// A rectangle of pixels whose predicted error is reported (and, with
    /// --target-error, aimed at), as [NAME=]ROW0:ROW1,COL0:COL1 (half-open,
    /// row 0 at the top); repeatable.
    #[arg(long = "window", value_name = "[NAME=]R0:R1,C0:C1")]
    windows: Vec<String>,
    /// Render only passes A to B-1 of a progressive render ("A..B"; "A.."
    /// with --time or --target-error) and write them as a partial render
    /// (--partial), for `photonmap merge`.
    #[arg(long, value_name = "A..B", requires = "partial")]
    pass_range: Option<String>,
    /// Also write the progressive render's exact sums and a manifest to
    /// this EXR (a partial render): what `merge` adds and `--resume` goes
    /// on from. Rewritten with the outputs, and written on Ctrl-C.
    #[arg(long, value_name = "PART.exr")]
    partial: Option<PathBuf>,
    /// Go on with the progressive render in this partial (same scene and
    /// settings), from the pass after its last, until --passes (counting the
    /// passes in the image), --time (this run's seconds) or --target-error:
    /// one is needed. --partial may name the same file: it is replaced,
    /// atomically, by the longer render.
    #[arg(long, value_name = "PART.exr", conflicts_with = "pass_range")]
    resume: Option<PathBuf>,
    /// Write a heat map of the per-pixel predicted error (progressive).
    #[arg(long, value_name = "FILE.png")]
    error_map: Option<PathBuf>,
    /// Show each progressive pass in the tev image viewer listening at
    /// HOST:PORT (tev's default: 127.0.0.1:14158).
    #[arg(long, value_name = "HOST:PORT")]
    display: Option<String>,
    /// How fast progressive photon mapping narrows its estimates (Knaus &
    /// Zwicker's alpha): pass i uses k and squared radius caps times
    /// prod_{j<i} (j + alpha - 1) / j.
    #[arg(long, default_value_t = DEFAULT.alpha, value_parser = parse_alpha)]
    alpha: f32,
    /// Photons emitted for the global map, per pass (1e6, 2.5e5 and 1000000
    /// all work) [default: 1e6; 2.5e5 for progressive renders].
    #[arg(long, value_parser = parse_count)]
    photons: Option<u64>,
    /// Photons emitted towards mirrors and glass [default: as --photons].
    #[arg(long, value_parser = parse_count)]
    caustic_photons: Option<u64>,
    /// Camera samples per pixel (a scrambled Sobol sequence, continued
    /// from pass to pass)
    /// [default: 4, or rays_per_pixel_edge squared from a scene file; 1 for
    /// progressive renders].
    #[arg(long, value_parser = count(1, 1_000_000))]
    spp: Option<u32>,
    /// Seed of every random stream: the same image on any number of threads.
    #[arg(long, default_value_t = DEFAULT.seed, value_parser = parse_seed)]
    seed: u64,
    /// Eye position: 1 = (-2,0,0), 53 degree view; 2 = (-1,0,0), 90 degrees.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    eye: Option<u8>,
    /// Worker threads [default: all cores].
    #[arg(long, value_parser = count(1, 4096))]
    threads: Option<u32>,
    /// Image width in pixels [default: 800, or the scene file's]. A size of
    /// another shape than the camera's widens a look-at camera's view; a
    /// four-corner camera's plane must have the image's shape.
    #[arg(long, value_parser = count(1, 65_536))]
    width: Option<u32>,
    /// Image height in pixels [default: 800, or the scene file's].
    #[arg(long, value_parser = count(1, 65_536))]
    height: Option<u32>,
    /// Nearest photons per global-map irradiance estimate (at least 2: the
    /// estimate counts those strictly inside the k-th photon's distance).
    #[arg(long, default_value_t = DEFAULT.k_global as u32, value_parser = count(2, 100_000))]
    k: u32,
    /// Nearest photons per caustic estimate (at least 2).
    #[arg(long, default_value_t = DEFAULT.k_caustic as u32, value_parser = count(2, 100_000))]
    k_caustic: u32,
    /// Largest search radius of a global-map estimate, in scene units
    /// [default: 5% of the scene's diagonal].
    #[arg(long, value_parser = parse_radius)]
    max_radius: Option<f32>,
    /// Largest search radius of a caustic estimate [default: 1% of the diagonal].
    #[arg(long, value_parser = parse_radius)]
    caustic_radius: Option<f32>,
    /// Final-gather rays per diffuse camera hit (0: no indirect light).
    #[arg(long, default_value_t = DEFAULT.gather_rays, value_parser = count(0, 65_536))]
    gather_rays: u32,
    /// Of the gather rays, how many are aimed at the mirrors, glass and bright
    /// spots a point sees, if any; one at least stays cosine (0: all do).
    #[arg(long, default_value_t = DEFAULT.aimed_gather_rays, value_parser = count(0, 65_536))]
    aimed_gather_rays: u32,
    /// Shadow rays per light per diffuse camera hit.
    #[arg(long, default_value_t = DEFAULT.shadow_rays, value_parser = count(1, 65_536))]
    shadow_rays: u32,
    /// Irradiance is precomputed at every N-th stored global photon, and
    /// final-gather rays read the nearest precomputed value [default: k / 6,
    /// 16 at k = 100, following k down in progressive passes].
    #[arg(long, value_parser = count(1, 65_536))]
    cache_stride: Option<u32>,
    /// A pixel's later camera samples reuse its last caustic estimate where
    /// they land on the same surface within this fraction of that
    /// estimate's radius (0 to 1; 0: every sample makes its own).
    #[arg(long, default_value_t = DEFAULT.caustic_reuse, value_parser = parse_fraction)]
    caustic_reuse: f32,
    /// Samples of the light seen in pixels on the rim of a light's image
    /// (directly or in mirrors and glass; 0: no extra samples).
    #[arg(long, default_value_t = DEFAULT.edge_spp, value_parser = count(0, 1_000_000))]
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
    /// metric of tools/metrics.py) and print the numbers.
    #[arg(long, value_name = "REF.exr")]
    reference: Option<PathBuf>,
    /// No progress bars and no summary.
    #[arg(short, long)]
    quiet: bool,
}

/// How a render ended.
pub enum Outcome {
    Done,
    /// Stopped by SIGINT/SIGTERM (what it had is written): exit 130.
    Interrupted,
}

/// The passes this run renders, and from what.
struct Plan {
    start: Accumulation,
    first: u32,
    budget: Budget,
    /// The parts already in `start` (resumed).
    parts: Vec<Part>,
}

pub fn run(cli: RenderArgs) -> Result<Outcome, Error> {
    let start = Instant::now();
    let outputs = Outputs {
        images: cli.outputs.iter().chain(&cli.more_outputs).cloned().collect(),
        partial: cli.partial.clone(),
        error_map: cli.error_map.clone(),
    };
    if outputs.is_empty() {
        return Err(Error::Invalid("no output file given (e.g. photonmap out.exr)".into()));
    }
    let windows = parse_windows(&cli.windows).map_err(Error::Invalid)?;
    let progressive = cli.passes.is_some()
        || cli.time.is_some()
        || cli.target_error.is_some()
        || cli.pass_range.is_some()
        || cli.resume.is_some();
    if !progressive {
        for (given, what) in [(cli.partial.is_some(), "--partial"), (cli.error_map.is_some(), "--error-map")] {
            if given {
                return Err(Error::Invalid(format!(
                    "{what} needs a progressive render: give --passes, --time or --target-error"
                )));
            }
        }
    }
    // Every output is checked before any time is spent loading or rendering.
    outputs.check_writable()?;
    let reference = cli.reference.as_deref().map(read_exr).transpose()?;
    let resumed = cli.resume.as_deref().map(read_partial).transpose()?;
    if let Some(threads) = cli.threads {
        threads_within_cores(threads, cli.quiet);
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads as usize)
            .build_global()
            .map_err(|e| Error::Invalid(format!("--threads: {e}")))?;
    }

    let mut integrator = cli.integrator.map_or(Method::Photon, |m| m.0);
    let loading = Instant::now();
    let wait = Wait::start(Mode::detect(cli.quiet), loading_line(cli.scene.as_deref()));
    let (mut scene, file_spp, scene_id) = match &cli.scene {
        None => {
            let eye = if cli.eye == Some(2) { Eye::Two } else { Eye::One };
            let name = format!("built-in TNCG15 room, eye {}", if eye == Eye::Two { 2 } else { 1 });
            (Scene::tncg15(eye), 4, SceneId::built_in(&name))
        }
        Some(path) if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("xml")) => {
            let options =
                photonmap::scene::mitsuba::Options { defines: cli.defines.clone(), substitute: cli.substitute };
            let mut imported =
                photonmap::scene::mitsuba::load(path, &options).map_err(|e| Error::Invalid(e.to_string()))?;
            match (imported.photon_limit.take(), cli.integrator) {
                (Some(e), Some(MethodArg(Method::Photon))) => {
                    if !cli.substitute {
                        return Err(Error::Invalid(e.to_string()));
                    }
                    imported.substitutions.push(format!("{e} (rendered with paths of every length)"));
                    imported.file.parts.paths.max_depth = None;
                }
                (Some(_), None) => {
                    integrator = Method::Path;
                    if !cli.quiet {
                        let depth = imported.file.parts.paths.max_depth.unwrap_or(0);
                        eprintln!(
                            "photonmap: {}: the integrator's max_depth {depth} stops paths at {depth} vertices, which \
                             the path tracer does exactly and photon mapping cannot: rendering with --integrator path",
                            path.display()
                        );
                    }
                }
                _ => {}
            }
            for s in &imported.substitutions {
                eprintln!("substituted: {s}");
            }
            let mut id = SceneId::from_files(path, &imported.inputs[1..])
                .map_err(|e| Error::Io { path: path.clone(), source: e })?;
            id.substitutions = imported.substitutions;
            (Scene::from_parts(imported.file.parts), imported.spp, id)
        }
        Some(path) => {
            if !cli.defines.is_empty() || cli.substitute {
                return Err(Error::Invalid(format!(
                    "{}: -D and --substitute are for Mitsuba scenes (.xml)",
                    path.display()
                )));
            }
            let file = photonmap::scene::file::load(path).map_err(|e| Error::Invalid(e.to_string()))?;
            if !file.not_physical.is_empty() {
                let all: Vec<String> = file.not_physical.iter().map(|e| e.to_string()).collect();
                return Err(Error::Invalid(format!(
                    "{}\n(the `trace` program renders this scene; photonmap cannot honour these)",
                    all.join("\n")
                )));
            }
            let id =
                SceneId::from_files(path, &file.meshes).map_err(|e| Error::Io { path: path.clone(), source: e })?;
            let n = file.rays_per_pixel_edge;
            (Scene::from_parts(file.parts), n * n, id)
        }
    };
    wait.finish();
    let load_time = loading.elapsed();
    let mut inputs: Vec<(&str, &std::path::Path)> = scene_id
        .inputs
        .iter()
        .enumerate()
        .map(|(i, p)| (if i == 0 { "scene file" } else { "mesh" }, p.as_path()))
        .collect();
    inputs.extend(cli.reference.as_deref().map(|p| ("--reference", p)));
    inputs.extend(cli.resume.as_deref().map(|p| ("--resume partial", p)));
    outputs.check_not_inputs(&inputs, cli.resume.as_deref())?;
    if scene.lights.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: the scene has no light (an emissive shape or a [[lights]] entry), so its image is black",
            scene_id.name
        )));
    }
    if let Some(path) = &cli.reference {
        reference_shows(path, &scene_id, cli.quiet)?;
    }
    if integrator == Method::Path {
        path_tracer_sees(&scene, cli.quiet)?;
    }

    let (width, height) = match &resumed {
        Some(p) => (cli.width.unwrap_or(p.manifest.width), cli.height.unwrap_or(p.manifest.height)),
        None => (cli.width.unwrap_or(scene.camera.width), cli.height.unwrap_or(scene.camera.height)),
    };
    scene.camera = scene.camera.fit(width, height).map_err(|e| Error::Invalid(format!("{}: {e}", scene_id.name)))?;
    let (photons, spp) = match progressive {
        true => (cli.photons.unwrap_or(PROGRESSIVE_PHOTONS), cli.spp.unwrap_or(PROGRESSIVE_SPP)),
        false => (cli.photons.unwrap_or(DEFAULT.photons), cli.spp.unwrap_or(file_spp)),
    };
    let settings = Settings {
        method: integrator,
        alpha: cli.alpha,
        photons,
        caustic_photons: cli.caustic_photons.unwrap_or(photons),
        spp,
        seed: cli.seed,
        width,
        height,
        k_global: cli.k as usize,
        k_caustic: cli.k_caustic as usize,
        r_global: cli.max_radius,
        r_caustic: cli.caustic_radius,
        gather_rays: cli.gather_rays,
        aimed_gather_rays: cli.aimed_gather_rays,
        shadow_rays: cli.shadow_rays,
        edge_spp: cli.edge_spp,
        cache_stride: cli.cache_stride.map(|n| n as usize),
        caustic_reuse: cli.caustic_reuse,
        skip: !cli.no_skip,
    };
    if let Some(reference) = &reference {
        reduction_factor((width, height), (reference.width, reference.height))
            .map_err(|e| Error::Invalid(format!("--reference: {e}")))?;
        let bad = reference.pixels.iter().filter(|c| !c.is_finite()).count();
        if bad > 0 {
            return Err(Error::Invalid(format!(
                "--reference: {bad} pixels hold non-finite values; a reference must be finite to score against"
            )));
        }
    }
    for w in &windows {
        if w.rows.1 > height || w.cols.1 > width {
            return Err(Error::Invalid(format!(
                "--window {}: rows {}:{} and columns {}:{} reach outside the {width}x{height} image",
                w.name, w.rows.0, w.rows.1, w.cols.0, w.cols.1
            )));
        }
    }
    // Refuse before allocating: a map that cannot fit would abort the
    // process half-way, after minutes of work.
    if let Some(available) = available_memory() {
        let need = settings.estimated_peak_bytes(progressive);
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
    let manifest = Manifest {
        program: format!("photonmap {}", env!("CARGO_PKG_VERSION")),
        scene: scene_id.name.clone(),
        scene_hash: scene_id.hash.clone(),
        settings: settings_key(&settings),
        width,
        height,
        method: settings.method.name().into(),
        alpha: settings.alpha,
        passes: String::new(),
        parts: Vec::new(),
    };
    let plan = if progressive { Some(plan(&cli, &manifest, resumed, windows)?) } else { None };
    if !cli.quiet {
        if settings.photons == 0 {
            eprintln!("photonmap: warning: --photons 0: no global map, so indirect light is missing");
        }
        if settings.caustic_photons == 0 {
            eprintln!("photonmap: warning: no caustic photons: caustics are missing");
        }
    }
    let mode = Mode::detect(cli.quiet);
    let tonemap = cli.tonemap.tonemap();
    // From here a signal asks the render to stop and keep what it has.
    interrupt::keep_work();

    let Some(plan) = plan else {
        // A classic render: one pass, no error estimate.
        let (film, stats) = render(&scene, &settings, mode);
        if interrupt::requested() {
            eprintln!("photonmap: interrupted; a single-pass render has nothing to keep, nothing written");
            return Ok(Outcome::Interrupted);
        }
        let photons = stats.global_emitted + stats.caustic_emitted;
        let attributes = provenance(&scene_id, &settings, "0..1".into(), photons, start.elapsed().as_secs_f64());
        let written = Written { film: &film, error: None, attributes };
        let t = Instant::now();
        let files = write_outputs(&outputs, &written, None, tonemap, cli.exposure)?;
        finish(cli.quiet, &settings, &stats, load_time, t.elapsed(), start, &files, &film, reference.as_ref(), &[])?;
        if !cli.quiet {
            eprintln!(
                "  error        none estimated (a single pass; a progressive render, e.g. --time 60, estimates it)"
            );
        }
        return Ok(interrupted_while_writing());
    };

    let mut tev = match &cli.display {
        Some(address) => Some(
            Tev::connect(address, "photonmap", width, height)
                .map_err(|e| Error::Invalid(format!("--display {address}: cannot reach tev: {e}")))?,
        ),
        None => None,
    };
    let mut last_write = Instant::now();
    let mut target_watch = TargetWatch::new();
    let display = PassDisplay::new(mode, plan.budget.clone(), plan.first);
    let mut part = Part { passes: String::new(), photons: 0, seconds: 0.0 };
    let partial_of = |acc: &Accumulation, part: &Part| Partial {
        manifest: Manifest { parts: plan.parts.iter().cloned().chain([part.clone()]).collect(), ..manifest.clone() },
        accumulation: acc.clone(),
    };
    let run = render_passes(&scene, &settings, plan.start.clone(), plan.first, &plan.budget, |report| {
        display.update(report);
        target_watch.check(&plan.budget, report, cli.quiet);
        if let Some(t) = &mut tev {
            if let Err(e) = t.update(report.film) {
                eprintln!("photonmap: warning: --display: {e}; the render goes on without it");
                tev = None;
            }
        }
        if last_write.elapsed().as_secs_f64() > REWRITE_SECONDS {
            part.passes = format!("{}..{}", plan.first, plan.first + report.rendered);
            part.seconds = start.elapsed().as_secs_f64();
            part.photons = report.photons;
            let photons = plan.parts.iter().map(|p| p.photons).sum::<u64>() + part.photons;
            let passes = report.accumulation.passes.to_string();
            let attributes = provenance(&scene_id, &settings, passes, photons, part.seconds);
            let written = Written { film: report.film, error: report.error, attributes };
            let partial = outputs.partial.as_ref().map(|_| partial_of(report.accumulation, &part));
            // A checkpoint that cannot be written (a full disk, a directory
            // gone) is said and tried again at the next one and at the end:
            // the passes are still in memory, and stopping would lose them.
            if let Err(e) = write_outputs(&outputs, &written, partial.as_ref(), tonemap, cli.exposure) {
                eprintln!("photonmap: warning: {e}; the render goes on and writes again in {REWRITE_SECONDS} s");
            }
            last_write = Instant::now();
        }
        ControlFlow::Continue(())
    });
    display.finish();
    let film = run.film();
    let rendered = run.stats.passes;
    part.passes = format!("{}..{}", plan.first, plan.first + rendered);
    part.photons = run.stats.global_emitted + run.stats.caustic_emitted;
    part.seconds = start.elapsed().as_secs_f64();
    let photons = plan.parts.iter().map(|p| p.photons).sum::<u64>() + part.photons;
    let attributes = provenance(&scene_id, &settings, run.accumulation.passes.to_string(), photons, part.seconds);
    let written = Written { film: &film, error: run.error.as_ref(), attributes };
    let t = Instant::now();
    let files = if rendered == 0 && plan.start.passes.is_empty() {
        Vec::new()
    } else {
        let partial = outputs.partial.as_ref().map(|_| partial_of(&run.accumulation, &part));
        write_outputs(&outputs, &written, partial.as_ref(), tonemap, cli.exposure)?
    };
    finish(
        cli.quiet,
        &settings,
        &run.stats,
        load_time,
        t.elapsed(),
        start,
        &files,
        &film,
        reference.as_ref(),
        &run.predictions,
    )?;
    if !cli.quiet {
        let why = match run.stopped {
            Stopped::Passes => "the passes asked for are done".to_string(),
            Stopped::Time => "--time is up".to_string(),
            Stopped::TargetError => "--target-error is reached".to_string(),
            Stopped::Interrupted => "interrupted; the passes finished are written".to_string(),
            Stopped::Caller => "an output could not be written".to_string(),
        };
        eprintln!(
            "  stopped      {why} ({} in the image, {rendered} by this run)",
            counted(run.accumulation.passes.count() as u64, "pass", "passes")
        );
    }
    Ok(if run.stopped == Stopped::Interrupted { Outcome::Interrupted } else { interrupted_while_writing() })
}

/// The progressive plan: where to start, when to stop.
fn plan(cli: &RenderArgs, manifest: &Manifest, resumed: Option<Partial>, windows: Vec<Window>) -> Result<Plan, Error> {
    let mut budget = Budget { end: cli.passes, seconds: cli.time, target_error: cli.target_error, windows };
    // A target too small to reach would run forever: a week is the
    // longest run, as for --time (said when a prediction shows it).
    if budget.target_error.is_some() && budget.seconds.is_none() {
        budget.seconds = Some(WEEK);
    }
    if let Some(text) = &cli.pass_range {
        let (first, end) = match text.strip_suffix("..") {
            Some(a) => (parse_range(a).map_err(|e| Error::Invalid(format!("--pass-range {e}")))?.start, None),
            None => {
                let r = parse_range(text).map_err(|e| Error::Invalid(format!("--pass-range {e}")))?;
                (r.start, Some(r.end))
            }
        };
        if end.is_none() && cli.time.is_none() && cli.target_error.is_none() {
            return Err(Error::Invalid(format!(
                "--pass-range {text}: an open range needs --time or --target-error to end it"
            )));
        }
        if cli.passes.is_some() {
            return Err(Error::Invalid("--pass-range gives the passes; --passes cannot be given with it".into()));
        }
        budget.end = end;
        let start = Accumulation::new(manifest.width, manifest.height);
        return Ok(Plan { start, first, budget, parts: Vec::new() });
    }
    if budget.end.is_none() && budget.seconds.is_none() && budget.target_error.is_none() {
        let what = if cli.resume.is_some() { "--resume" } else { "a progressive render" };
        return Err(Error::Invalid(format!("{what} needs --passes, --time or --target-error to end it")));
    }
    if let Some(p) = resumed {
        let path = cli.resume.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
        if let Some(why) = p.manifest.mismatch(manifest) {
            return Err(Error::Invalid(format!("--resume {path}: not this render's partial: {why}")));
        }
        let first = p.accumulation.passes.end();
        if budget.end.is_some_and(|n| n <= first) {
            return Err(Error::Invalid(format!(
                "--resume {path}: it holds passes {} already; --passes {} asks for no more",
                p.accumulation.passes,
                budget.end.unwrap_or(0)
            )));
        }
        return Ok(Plan { first, budget, parts: p.manifest.parts, start: p.accumulation });
    }
    Ok(Plan { start: Accumulation::new(manifest.width, manifest.height), first: 0, budget, parts: Vec::new() })
}

/// What a long load says: the scene file and its size.
fn loading_line(scene: Option<&std::path::Path>) -> String {
    match scene {
        Some(path) => {
            let size = std::fs::metadata(path).map_or(String::new(), |m| format!(" ({:.1} MB)", m.len() as f64 / 1e6));
            format!("photonmap: loading {}{size}", path.display())
        }
        None => "photonmap: building the built-in room".into(),
    }
}

/// A signal that came while the outputs were written (they are complete:
/// each is renamed into place whole) still ends the run as interrupted, so
/// a script does not take it for one that ran its course.
fn interrupted_while_writing() -> Outcome {
    if interrupt::requested() {
        eprintln!("photonmap: interrupted while writing; the outputs written are complete");
        Outcome::Interrupted
    } else {
        Outcome::Done
    }
}
