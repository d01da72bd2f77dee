//! Checks that keep a render from giving a wrong answer without a word:
//! a --reference of another scene, light the path tracer cannot find, a
//! --target-error out of reach, more threads than cores.

use photonmap::error::Error;
use photonmap::integrator::unseen::specular_shares;
use photonmap::output::read_header;
use photonmap::progress::seconds_to_target;
use photonmap::provenance::SceneId;
use photonmap::render::{Budget, PassReport};
use photonmap::scene::Scene;
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

/// Says once that --target-error will not be reached within the run's
/// time (--time, or the week a run may last), as soon as a prediction shows
/// it.
pub struct TargetWatch {
    said: bool,
}

impl TargetWatch {
    pub fn new() -> Self {
        TargetWatch { said: false }
    }

    pub fn check(&mut self, budget: &Budget, report: &PassReport, quiet: bool) {
        if self.said || quiet {
            return;
        }
        let (Some(more), Some(seconds)) = (seconds_to_target(budget, report), budget.seconds) else { return };
        if more > seconds - report.elapsed.as_secs_f64() {
            self.said = true;
            let limit = if seconds == WEEK {
                format!("after a week ({WEEK} s, the longest run; --time stops it sooner)")
            } else {
                format!("at --time {seconds} s")
            };
            eprintln!(
                "photonmap: warning: --target-error {:e}: about {more:.2e} s more would be needed (the error \
                 falls as one over the square root of the passes); the render stops {limit} or at Ctrl-C, \
                 keeping the passes done",
                budget.target_error.unwrap_or(0.0)
            );
        }
    }
}

/// More threads than cores only add switching (2,048 threads turned a
/// 0.2 s render into 40 s); said, not refused: the image is the same.
pub fn threads_within_cores(threads: u32, quiet: bool) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if threads as usize > cores && !quiet {
        eprintln!(
            "photonmap: warning: --threads {threads} is more than the {cores} cores; the extra threads only add \
             overhead (the image is the same on any number)"
        );
    }
}
