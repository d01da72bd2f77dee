//! The files a run writes: checked before any rendering (each can be
//! created, none is an input, none is named twice), then written
//! atomically, every one of them whatever happens to the others: images
//! (EXRs with their provenance and, where there is one, the error
//! estimate's layers), the error heat map, the partial render.

use crate::error::Error;
use crate::film::{Film, ToneMap};
use crate::metrics::heat_rgb8;
use crate::output::partial::{write_partial, Partial};
use crate::output::{check_writable, same_file, write_rgb8_image, write_with, Extras, Format};
use crate::render::error_estimate::ErrorEstimate;
use std::path::{Path, PathBuf};

/// Every output of a run, by role.
#[derive(Debug, Default)]
pub struct Outputs {
    pub images: Vec<PathBuf>,
    pub partial: Option<PathBuf>,
    pub error_map: Option<PathBuf>,
}

impl Outputs {
    pub fn all(&self) -> Vec<(&'static str, &Path)> {
        let mut all: Vec<(&'static str, &Path)> = self.images.iter().map(|p| ("output", p.as_path())).collect();
        all.extend(self.partial.as_deref().map(|p| ("--partial", p)));
        all.extend(self.error_map.as_deref().map(|p| ("--error-map", p)));
        all
    }

    pub fn is_empty(&self) -> bool {
        self.images.is_empty() && self.partial.is_none()
    }

    /// Each output can be written, in a format its role can take, and none
    /// is named twice.
    pub fn check_writable(&self) -> Result<(), Error> {
        let all = self.all();
        for (i, (role, path)) in all.iter().enumerate() {
            let format = check_writable(path)?;
            // Found here, not at the first write: a partial named .png was
            // refused only after the passes it was to hold were rendered.
            let wrong = match (*role, format) {
                ("--partial", Format::Png | Format::Ppm) => Some("a partial render is an .exr file (exact sums)"),
                ("--error-map", Format::Exr) => Some("the error map is an 8-bit picture: .png or .ppm"),
                _ => None,
            };
            if let Some(why) = wrong {
                return Err(Error::Invalid(format!("{role} {}: {why}", path.display())));
            }
            if let Some((other, _)) = all[..i].iter().find(|(_, p)| same_file(p, path)) {
                let roles =
                    if *other == *role { format!("twice as an {role}") } else { format!("as {other} and as {role}") };
                return Err(Error::Invalid(format!(
                    "{}: named {roles}; each output needs its own file",
                    path.display()
                )));
            }
        }
        Ok(())
    }

    /// No output is one of `inputs` (role, path), except that `--partial`
    /// may be the partial that `--resume` extends (it is replaced,
    /// atomically, by one holding more passes).
    pub fn check_not_inputs(&self, inputs: &[(&str, &Path)], resumed: Option<&Path>) -> Result<(), Error> {
        for (role, path) in self.all() {
            for (input_role, input) in inputs {
                if same_file(path, input) {
                    if role == "--partial" && resumed.is_some_and(|r| same_file(r, path)) {
                        continue;
                    }
                    return Err(Error::Invalid(format!(
                        "{}: the {role} is also the {input_role}; it would be overwritten (choose another name)",
                        path.display()
                    )));
                }
            }
        }
        Ok(())
    }
}

/// An image and what it is.
pub struct Written<'a> {
    pub film: &'a Film,
    pub error: Option<&'a ErrorEstimate>,
    /// How it was made (an EXR's header attributes).
    pub attributes: Vec<(String, String)>,
}

/// How 8-bit outputs are made from radiance.
#[derive(Clone, Copy, Debug)]
pub struct Look {
    pub tonemap: ToneMap,
    pub exposure: f32,
}

/// Writes every output, each whatever becomes of the others; the first
/// failure is returned after all were tried. Returns the files written.
pub fn write_outputs(
    outputs: &Outputs,
    w: &Written,
    partial: Option<&Partial>,
    look: Look,
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
        record(path, write_with(path, w.film, look.tonemap, look.exposure, &extras));
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
