//! Checks that keep a render from giving a wrong answer without a word,
//! or from failing after minutes of work: a --reference of another scene
//! or size, light the path tracer cannot find, windows outside the image,
//! more memory than there is, more threads than cores.

use crate::error::Error;
use crate::film::Film;
use crate::integrator::unseen::specular_shares;
use crate::memory::available_memory;
use crate::metrics::{reduction_factor, Window};
use crate::output::read_header;
use crate::provenance::SceneId;
use crate::render::settings::Settings;
use crate::scene::Scene;
use std::path::Path;

/// The name the built-in room's default view goes by, which a reference
/// without provenance (the Mitsuba references) is taken to show.
const DEFAULT_VIEW: &str = "built-in TNCG15 room, eye 1";

/// A reference must show the scene rendered: one whose header names its
/// scene (photonmap's provenance) must name this one, else the scores
/// would compare two views. One that names none is taken for the default
/// view, and said to be so where the render is another.
pub fn reference_shows(reference: &Path, scene: &SceneId, quiet: bool) -> Result<(), Error> {
    let header = read_header(reference)?;
    match (header.get("scene"), header.get("scene_sha256")) {
        (Some(name), Some(hash)) if hash != scene.hash => Err(Error::Invalid(format!(
            "--reference {}: it is a render of {name}, this is a render of {}; the scores would compare \
             different scenes or views (`photonmap compare` scores any two images)",
            reference.display(),
            scene.name
        ))),
        (None, _) | (_, None) if scene.name != DEFAULT_VIEW && !quiet => {
            eprintln!(
                "photonmap: warning: --reference {} does not say what it shows (no provenance in its header); \
                 it is scored as a render of {}, with the default view's caustic window",
                reference.display(),
                scene.name
            );
            Ok(())
        }
        _ => Ok(()),
    }
}

/// The path tracer finds a point or directional light only by shadow rays,
/// which no mirror or glass passes: a delta light that reaches the scene
/// only through them is refused (its light would be missing, a black image
/// where it is the only one); one whose power partly meets them first is
/// warned of (its caustics and reflections are missing).
pub fn path_tracer_sees(scene: &Scene, quiet: bool) -> Result<(), Error> {
    for s in specular_shares(scene) {
        let light = scene.lights[s.light].describe();
        if s.share >= 1.0 {
            return Err(Error::Invalid(format!(
                "--integrator path: {light} reaches the scene only through mirrors or glass; a path tracer \
                 cannot find a point or directional light through a specular surface, so its light would be \
                 missing (use --integrator photon, which carries it from the light)"
            )));
        }
        if s.share >= 0.01 && !quiet {
            eprintln!(
                "photonmap: warning: --integrator path: {:.0}% of the power of {light} first meets mirrors or \
                 glass; a path tracer misses that light (its caustics, its image in a mirror)",
                100.0 * s.share
            );
        }
    }
    Ok(())
}

/// The longest run a progressive render may take when nothing else ends it
/// earlier: a week, as for --time.
pub const WEEK: f64 = 7.0 * 24.0 * 3600.0;

/// Renders on `threads` worker threads. More threads than cores only add
/// switching (2,048 threads turned a 0.2 s render into 40 s): said where
/// `warn`, not refused, as the image is the same.
pub fn use_threads(threads: u32, warn: bool) -> Result<(), Error> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if threads as usize > cores && warn {
        eprintln!(
            "photonmap: warning: --threads {threads} is more than the {cores} cores; the extra threads only add \
             overhead (the image is the same on any number)"
        );
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads as usize)
        .build_global()
        .map_err(|e| Error::Invalid(format!("--threads: {e}")))
}

/// A reference the render can be scored against: its size a divisor of
/// the render's, every pixel finite.
pub fn reference_fits(reference: &Film, width: u32, height: u32) -> Result<(), Error> {
    reduction_factor((width, height), (reference.width, reference.height))
        .map_err(|e| Error::Invalid(format!("--reference: {e}")))?;
    let bad = reference.pixels.iter().filter(|c| !c.is_finite()).count();
    if bad > 0 {
        return Err(Error::Invalid(format!(
            "--reference: {bad} pixels hold non-finite values; a reference must be finite to score against"
        )));
    }
    Ok(())
}

/// Every --window inside the image.
pub fn windows_fit(windows: &[Window], width: u32, height: u32) -> Result<(), Error> {
    for w in windows {
        if w.rows.1 > height || w.cols.1 > width {
            return Err(Error::Invalid(format!(
                "--window {}: rows {}:{} and columns {}:{} reach outside the {width}x{height} image",
                w.name, w.rows.0, w.rows.1, w.cols.0, w.cols.1
            )));
        }
    }
    Ok(())
}

/// Refused before allocating: a map that cannot fit would abort the
/// process half-way, after minutes of work.
pub fn memory_fits(settings: &Settings, progressive: bool) -> Result<(), Error> {
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
    Ok(())
}
