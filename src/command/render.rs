//! `photonmap`'s render, its flags parsed: check every output, load the
//! scene, check what would give a wrong answer without a word, plan the
//! passes (one, a range, on from a partial), drive them with the observers
//! the program chose, write, summarise.

use super::checks::{memory_fits, path_tracer_sees, reference_fits, reference_shows, windows_fit, WEEK};
use super::load::{load, Loaded};
use super::observers::{PassDisplay, PeriodicWriter, TargetWatch, TevPreview};
use super::outputs::{write_outputs, Look, Outputs, Written};
use super::summary::finish;
use crate::error::Error;
use crate::film::accumulation::{parse_range, Accumulation};
use crate::interrupt;
use crate::metrics::Window;
use crate::output::partial::{read_partial, Manifest, Part, Partial};
use crate::output::read_exr;
use crate::progress::Mode;
use crate::provenance::{settings_key, Provenance};
use crate::render::settings::{
    default_global_photons, default_vertex_rays, progressive_caustics, Settings, DEFAULT, PROGRESSIVE_PHOTONS,
    PROGRESSIVE_SPP,
};
use crate::render::{drive, Budget, Method, Observer, Plan, Stopped};
use crate::scene::Eye;
use crate::stats::counted;
use std::path::PathBuf;
use std::time::Instant;

/// A render as the command line asks it.
pub struct Request {
    /// A scene file (TOML or Mitsuba XML), or the built-in room seen from `eye`.
    pub scene: Option<PathBuf>,
    pub eye: Eye,
    /// A Mitsuba scene's parameters (-D) and stand-ins (--substitute).
    pub defines: Vec<(String, String)>,
    pub substitute: bool,
    pub outputs: Outputs,
    /// None: photon mapping, or what the scene needs.
    pub method: Option<Method>,
    /// The progressive budget: passes (in the image), seconds, a target
    /// error over the windows.
    pub passes: Option<u32>,
    pub seconds: Option<f64>,
    pub target_error: Option<f64>,
    pub windows: Vec<Window>,
    /// Passes "A..B" or "A.." (for a partial).
    pub pass_range: Option<String>,
    /// A partial to go on from.
    pub resume: Option<PathBuf>,
    /// None: the defaults, which differ for progressive renders and scene
    /// files.
    pub photons: Option<u64>,
    pub caustic_photons: Option<u64>,
    /// None: the default, which differs for progressive renders.
    pub k_caustic: Option<usize>,
    /// None: the defaults, which differ for photon mapping in a scene with
    /// media.
    pub gather_rays: Option<u32>,
    pub shadow_rays: Option<u32>,
    pub spp: Option<u32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Every other setting (the method, photons, samples and size above
    /// are decided here).
    pub settings: Settings,
    pub look: Look,
    pub reference: Option<PathBuf>,
    pub quiet: bool,
    /// The observers chosen: a tev viewer at HOST:PORT, and how often the
    /// outputs of a progressive render are rewritten.
    pub display: Option<String>,
    pub rewrite_seconds: f64,
}

impl Request {
    /// Whether it asks for passes averaged.
    pub fn progressive(&self) -> bool {
        self.passes.is_some()
            || self.seconds.is_some()
            || self.target_error.is_some()
            || self.pass_range.is_some()
            || self.resume.is_some()
    }
}

/// How a render ended.
#[derive(Debug, PartialEq, Eq)]
pub enum Outcome {
    Done,
    /// Stopped by SIGINT/SIGTERM (what it had is written): exit 130.
    Interrupted,
}

pub fn run(req: Request) -> Result<Outcome, Error> {
    let start = Instant::now();
    let outputs = &req.outputs;
    if outputs.is_empty() {
        return Err(Error::Invalid("no output file given (e.g. photonmap out.exr)".into()));
    }
    let progressive = req.progressive();
    if !progressive {
        for (given, what) in [(outputs.partial.is_some(), "--partial"), (outputs.error_map.is_some(), "--error-map")] {
            if given {
                return Err(Error::Invalid(format!(
                    "{what} needs a progressive render: give --passes, --time or --target-error"
                )));
            }
        }
    }
    // Every output is checked before any time is spent loading or rendering.
    outputs.check_writable()?;
    let reference = req.reference.as_deref().map(read_exr).transpose()?;
    let resumed = req.resume.as_deref().map(read_partial).transpose()?;
    let loading = Instant::now();
    let Loaded { mut scene, spp: file_spp, id: scene_id, method } = load(&req)?;
    let load_time = loading.elapsed();
    let mut inputs: Vec<(&str, &std::path::Path)> = scene_id
        .inputs
        .iter()
        .enumerate()
        .map(|(i, p)| (if i == 0 { "scene file" } else { "mesh" }, p.as_path()))
        .collect();
    inputs.extend(req.reference.as_deref().map(|p| ("--reference", p)));
    inputs.extend(req.resume.as_deref().map(|p| ("--resume partial", p)));
    outputs.check_not_inputs(&inputs, req.resume.as_deref())?;
    if scene.lights.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: the scene has no light (an emissive shape or a [[lights]] entry), so its image is black",
            scene_id.name
        )));
    }
    if let Some(path) = &req.reference {
        reference_shows(path, &scene_id, req.quiet)?;
    }
    if method == Method::Path {
        path_tracer_sees(&scene, req.quiet)?;
    }

    let (width, height) = match &resumed {
        Some(p) => (req.width.unwrap_or(p.manifest.width), req.height.unwrap_or(p.manifest.height)),
        None => (req.width.unwrap_or(scene.camera.width), req.height.unwrap_or(scene.camera.height)),
    };
    scene.camera = scene.camera.fit(width, height).map_err(|e| Error::Invalid(format!("{}: {e}", scene_id.name)))?;
    let (photons, spp) = match progressive {
        true => (req.photons.unwrap_or(PROGRESSIVE_PHOTONS), req.spp.unwrap_or(PROGRESSIVE_SPP)),
        false => (req.photons.unwrap_or(DEFAULT.photons), req.spp.unwrap_or(file_spp)),
    };
    // A progressive pass given no photon counts takes more caustic photons
    // at a k that keeps the estimates' disks, where the scene has no media.
    let given_no_counts = progressive && req.photons.is_none() && req.caustic_photons.is_none();
    let (caustic_photons, k_caustic) = match given_no_counts {
        true => progressive_caustics(scene.media().is_some()),
        false => (req.caustic_photons.unwrap_or(photons), DEFAULT.k_caustic),
    };
    let k_caustic = req.k_caustic.unwrap_or(k_caustic);
    let photons = match req.photons {
        Some(given) => given,
        None => default_global_photons(photons, scene.media().is_some()),
    };
    let (gather_rays, shadow_rays) = default_vertex_rays(method, scene.media().is_some());
    let (gather_rays, shadow_rays) = (req.gather_rays.unwrap_or(gather_rays), req.shadow_rays.unwrap_or(shadow_rays));
    let settings = Settings {
        method,
        photons,
        caustic_photons,
        k_caustic,
        spp,
        width,
        height,
        gather_rays,
        shadow_rays,
        ..req.settings
    };
    if let Some(reference) = &reference {
        reference_fits(reference, width, height)?;
    }
    windows_fit(&req.windows, width, height)?;
    memory_fits(&settings, progressive)?;
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
    let (plan, parts) = match progressive {
        true => plan(&req, &manifest, resumed)?,
        false => (Plan::single(width, height), Vec::new()),
    };
    if !req.quiet {
        if settings.photons == 0 {
            eprintln!("photonmap: warning: --photons 0: no global map, so indirect light is missing");
        }
        if settings.caustic_photons == 0 {
            eprintln!("photonmap: warning: no caustic photons: caustics are missing");
        }
        // Volumetric photon mapping's camera pass gathers without aiming
        // and reads no reused caustic estimates: say so rather than
        // ignore a value the user set.
        if method == Method::Photon && scene.media().is_some() {
            let set = [
                ("--aimed-gather-rays", settings.aimed_gather_rays != DEFAULT.aimed_gather_rays),
                ("--caustic-reuse", settings.caustic_reuse != DEFAULT.caustic_reuse),
            ];
            for (flag, _) in set.iter().filter(|(_, given)| *given) {
                eprintln!("photonmap: warning: {flag} has no effect in a scene with participating media");
            }
        }
    }
    let mode = Mode::detect(req.quiet);
    let unit = settings.method.unit(&settings);
    let provenance = |passes: String, photons: u64, seconds: f64| {
        Provenance { scene: &scene_id, settings: &settings, passes, photons, seconds }.attributes()
    };
    // The observers: progress, the --target-error watch, tev, the outputs
    // rewritten every so often (with the partial of this run's passes).
    let mut display = progressive.then(|| PassDisplay::new(mode, plan.budget.clone(), plan.first));
    let mut watch = TargetWatch { budget: plan.budget.clone(), quiet: req.quiet, said: false };
    let mut tev = match (&req.display, progressive) {
        (Some(address), true) => Some(TevPreview::connect(address, width, height)?),
        _ => None,
    };
    let partial_of = |acc: &Accumulation, part: &Part| Partial {
        manifest: Manifest { parts: parts.iter().cloned().chain([part.clone()]).collect(), ..manifest.clone() },
        accumulation: acc.clone(),
    };
    let earlier_photons: u64 = parts.iter().map(|p| p.photons).sum();
    let mut writer = PeriodicWriter {
        every: req.rewrite_seconds,
        last: Instant::now(),
        first: plan.first,
        start,
        write: |report: &crate::render::PassReport, part: &Part| {
            let attributes =
                provenance(report.accumulation.passes.to_string(), earlier_photons + part.photons, part.seconds);
            let written = Written { film: report.film, error: report.error, attributes };
            let partial = outputs.partial.as_ref().map(|_| partial_of(report.accumulation, part));
            write_outputs(outputs, &written, partial.as_ref(), req.look).map(|_| ())
        },
    };
    let mut observers: Vec<&mut dyn Observer> = Vec::new();
    if let Some(display) = &mut display {
        observers.push(display);
    }
    observers.push(&mut watch);
    if let Some(tev) = &mut tev {
        observers.push(tev);
    }
    observers.push(&mut writer);
    // From here a signal asks the render to stop and keep what it has.
    interrupt::keep_work();
    let first = plan.first;
    let nothing_before = plan.start.passes.is_empty();
    let run = drive(&scene, &settings, unit.as_ref(), plan, mode, &mut observers);
    drop(observers);
    if !progressive && run.stopped == Stopped::Interrupted {
        eprintln!("photonmap: interrupted; a single-pass render has nothing to keep, nothing written");
        return Ok(Outcome::Interrupted);
    }
    let film = run.film();
    let rendered = run.stats.passes;
    let seconds = start.elapsed().as_secs_f64();
    let part = Part {
        passes: format!("{first}..{}", first + rendered),
        photons: run.stats.global_emitted + run.stats.caustic_emitted,
        seconds,
    };
    let passes = if progressive { run.accumulation.passes.to_string() } else { "0..1".into() };
    let written = Written {
        film: &film,
        error: run.error.as_ref(),
        attributes: provenance(passes, earlier_photons + part.photons, seconds),
    };
    let t = Instant::now();
    let files = if progressive && rendered == 0 && nothing_before {
        Vec::new()
    } else {
        let partial = outputs.partial.as_ref().map(|_| partial_of(&run.accumulation, &part));
        write_outputs(outputs, &written, partial.as_ref(), req.look)?
    };
    let ending = super::summary::Ending { load_time, write_time: t.elapsed(), start, files: &files };
    finish(req.quiet, &settings, unit.as_ref(), &run.stats, &ending, &film, reference.as_ref(), &run.predictions)?;
    if !req.quiet {
        if !progressive {
            eprintln!(
                "  error        none estimated (a single pass; a progressive render, e.g. --time 60, estimates it)"
            );
        } else {
            let why = match run.stopped {
                Stopped::Passes => "the passes asked for are done",
                Stopped::Time => "--time is up",
                Stopped::TargetError => "--target-error is reached",
                Stopped::Interrupted => "interrupted; the passes finished are written",
                Stopped::Caller => "an output could not be written",
            };
            eprintln!(
                "  stopped      {why} ({} in the image, {rendered} by this run)",
                counted(run.accumulation.passes.count() as u64, "pass", "passes")
            );
        }
    }
    Ok(if run.stopped == Stopped::Interrupted { Outcome::Interrupted } else { interrupted_while_writing() })
}

/// The progressive plan (where to start, when to stop) and the parts
/// already in its start (resumed).
fn plan(req: &Request, manifest: &Manifest, resumed: Option<Partial>) -> Result<(Plan, Vec<Part>), Error> {
    let windows = req.windows.clone();
    let mut budget = Budget { end: req.passes, seconds: req.seconds, target_error: req.target_error, windows };
    // A target too small to reach would run forever: a week is the
    // longest run, as for --time (said when a prediction shows it).
    if budget.target_error.is_some() && budget.seconds.is_none() {
        budget.seconds = Some(WEEK);
    }
    let empty = || Accumulation::new(manifest.width, manifest.height);
    if let Some(text) = &req.pass_range {
        let (first, end) = match text.strip_suffix("..") {
            Some(a) => (parse_range(a).map_err(|e| Error::Invalid(format!("--pass-range {e}")))?.start, None),
            None => {
                let r = parse_range(text).map_err(|e| Error::Invalid(format!("--pass-range {e}")))?;
                (r.start, Some(r.end))
            }
        };
        if end.is_none() && req.seconds.is_none() && req.target_error.is_none() {
            return Err(Error::Invalid(format!(
                "--pass-range {text}: an open range needs --time or --target-error to end it"
            )));
        }
        if req.passes.is_some() {
            return Err(Error::Invalid("--pass-range gives the passes; --passes cannot be given with it".into()));
        }
        budget.end = end;
        return Ok((Plan::passes(empty(), first, budget), Vec::new()));
    }
    if budget.end.is_none() && budget.seconds.is_none() && budget.target_error.is_none() {
        let what = if req.resume.is_some() { "--resume" } else { "a progressive render" };
        return Err(Error::Invalid(format!("{what} needs --passes, --time or --target-error to end it")));
    }
    if let Some(p) = resumed {
        let path = req.resume.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
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
        return Ok((Plan::passes(p.accumulation, first, budget), p.manifest.parts));
    }
    Ok((Plan::passes(empty(), 0, budget), Vec::new()))
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
