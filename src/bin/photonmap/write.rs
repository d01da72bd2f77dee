//! Writing a render's files: images (EXRs with their provenance and, where
//! there is one, the error estimate's layers), the error heat map, the
//! partial render.

use crate::outputs::Outputs;
use photonmap::error::Error;
use photonmap::film::{Film, ToneMap};
use photonmap::metrics::heat_rgb8;
use photonmap::output::partial::{write_partial, Partial};
use photonmap::output::{write_rgb8_image, write_with, Extras};
use photonmap::provenance::{Provenance, SceneId};
use photonmap::render::error_estimate::ErrorEstimate;
use photonmap::settings::Settings;
use std::path::PathBuf;

/// An image and what it is.
pub struct Written<'a> {
    pub film: &'a Film,
    pub error: Option<&'a ErrorEstimate>,
    /// How it was made (an EXR's header attributes).
    pub attributes: Vec<(String, String)>,
}

/// The header attributes of a render of `scene` with `settings`.
pub fn provenance(
    scene: &SceneId,
    settings: &Settings,
    passes: String,
    photons: u64,
    seconds: f64,
) -> Vec<(String, String)> {
    Provenance { scene, settings, passes, photons, seconds }.attributes()
}

/// Writes every output, each whatever becomes of the others; the first
/// failure is returned after all were tried. Returns the files written.
pub fn write_outputs(
    outputs: &Outputs,
    w: &Written,
    partial: Option<&Partial>,
    tonemap: ToneMap,
    exposure: f32,
) -> Result<Vec<PathBuf>, Error> {
    let mut extras = Extras { attributes: w.attributes.clone(), layers: Vec::new() };
    if let Some(e) = w.error {
        extras.attributes.push(("error_passes".into(), e.passes.to_string()));
        extras.layers =
            vec![("error".into(), e.error_film()), ("noise".into(), e.noise_film()), ("bias".into(), e.bias_film())];
    }
    let mut written = Vec::new();
    let mut first_error = None;
    let mut record = |path: &PathBuf, result: Result<(), Error>| match result {
        Ok(()) => written.push(path.clone()),
        Err(e) => {
            first_error.get_or_insert(e);
        }
    };
    for path in &outputs.images {
        record(path, write_with(path, w.film, tonemap, exposure, &extras));
    }
    if let Some(path) = &outputs.error_map {
        match w.error {
            Some(e) => {
                let (rgb, _) = heat_rgb8(&e.error_film(), None);
                record(path, write_rgb8_image(path, w.film.width, w.film.height, rgb));
            }
            None => eprintln!(
                "photonmap: warning: --error-map {}: too few passes for an error estimate yet",
                path.display()
            ),
        }
    }
    if let (Some(path), Some(p)) = (&outputs.partial, partial) {
        record(path, write_partial(path, p));
    }
    match first_error {
        Some(e) => Err(e),
        None => Ok(written),
    }
}
