//! The render methods: photon mapping (classic, and progressive as its
//! passes), path tracing and the Whitted tracer. Each is one unit: a row of
//! the [`Method`] table (its name, its bias model, its unit's
//! construction) and a [`RenderMethod`] that prepares each pass (a photon
//! stage, or nothing), gives the camera pass its integrator, and says its
//! lines of the summary. The driver ([`super::driver`]) runs any of them
//! the same way.

use super::camera_pass::{camera_pass, CameraPass};
use super::error_estimate::BiasModel;
use super::photon_stage::{shrink, PhotonMapping};
use super::tracers::{PathTracing, WhittedTracing};
use crate::film::Film;
use crate::integrator::Integrator;
use crate::progress::Mode;
use crate::render::settings::Settings;
use crate::scene::Scene;
use crate::stats::Stats;
use std::time::Instant;

/// The render methods: the one table of their names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// Photon mapping: direct light, caustic map, final gathering.
    #[default]
    Photon,
    /// Path tracing with next-event estimation (unbiased, the reference).
    Path,
    /// The CS475 Whitted ray tracer: the course's Phong shading, mirror
    /// bounces to a depth (the `trace` program).
    Whitted,
}

impl Method {
    pub const ALL: [Method; 3] = [Method::Photon, Method::Path, Method::Whitted];

    /// Its name: on command lines, in EXR headers and partial manifests.
    pub fn name(self) -> &'static str {
        match self {
            Method::Photon => "photon",
            Method::Path => "path",
            Method::Whitted => "whitted",
        }
    }

    /// What it does, in a summary's first line.
    pub fn title(self) -> &'static str {
        match self {
            Method::Photon => "photon mapping",
            Method::Path => "path tracing",
            Method::Whitted => "Whitted ray tracing",
        }
    }

    /// What it is, for a command's help.
    pub fn description(self) -> &'static str {
        match self {
            Method::Photon => "Photon mapping: direct light, caustic map, final gathering.",
            Method::Path => "Path tracing with next-event estimation (unbiased, the reference).",
            Method::Whitted => "The CS475 Whitted ray tracer (Phong shading, mirror bounces).",
        }
    }

    /// Whether it estimates radiance (what `photonmap` renders); the
    /// Whitted tracer shades with the course's formula instead.
    pub fn estimates_radiance(self) -> bool {
        !matches!(self, Method::Whitted)
    }

    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// How its passes are biased, for the error estimate (`alpha`:
    /// progressive photon mapping's narrowing).
    pub fn bias(self, alpha: f32) -> BiasModel {
        match self {
            Method::Photon => BiasModel::Shrinking { alpha },
            Method::Path | Method::Whitted => BiasModel::None,
        }
    }

    /// Its unit, rendering with `settings`.
    pub fn unit(self, settings: &Settings) -> Box<dyn RenderMethod> {
        match self {
            Method::Photon => Box::new(PhotonMapping { settings: *settings }),
            Method::Path => Box::new(PathTracing { shadow_rays: settings.shadow_rays, skip: settings.skip }),
            Method::Whitted => Box::new(WhittedTracing { max_depth: WhittedTracing::DEPTH }),
        }
    }
}

impl BiasModel {
    /// Pass `pass`'s shrink factor relative to pass 0's (0 where the passes
    /// do not narrow).
    pub fn shrink(self, pass: u32) -> f64 {
        match self {
            BiasModel::Shrinking { alpha } => shrink(alpha, pass),
            BiasModel::None => 0.0,
        }
    }
}

/// A render method's unit: one pass of it, and what it says of its passes.
pub trait RenderMethod: Sync {
    /// Its row of the table.
    fn method(&self) -> Method;

    /// Renders pass `camera.pass`: prepares what the pass needs (a photon
    /// stage, or nothing), then runs the camera pass with its integrator
    /// ([`shoot`]). `guide`: as for [`camera_pass`].
    fn pass(
        &self,
        scene: &Scene,
        camera: &CameraPass,
        progress: Mode,
        guide: &mut super::Guide,
        stats: &mut Stats,
    ) -> Film;

    /// Its part of a render's summary.
    fn summary(&self, _stats: &Stats) -> MethodSummary {
        MethodSummary::default()
    }
}

/// A method's part of the summary: its lines after the scene's load, what
/// its camera pass did besides tracing (", 4 gather"), what it skipped.
#[derive(Debug, Default)]
pub struct MethodSummary {
    pub lines: Vec<String>,
    pub camera: String,
    pub skipped: Vec<String>,
}

/// The camera pass of a method's pass with `integrator`, timed and counted
/// into `stats`.
pub fn shoot<I: Integrator>(
    camera: &CameraPass,
    integrator: &I,
    progress: Mode,
    guide: &mut super::Guide,
    stats: &mut Stats,
) -> Film {
    let t = Instant::now();
    let shot = camera_pass(camera, integrator, progress, guide);
    stats.camera_time = t.elapsed();
    stats.camera = shot.counters;
    stats.edge_pixels = shot.edge_pixels;
    stats.edge_spp = shot.edge_spp;
    stats.edge_spp_max = shot.edge_spp_max;
    stats.adaptive_pixels = shot.adaptive_pixels;
    stats.adaptive_samples = shot.adaptive_samples;
    shot.film
}
