//! The scene file: TOML read with serde ([`defs`]), checked field by field
//! and turned into [`SceneParts`] ([`build`]). The format's reference is
//! notes/scene-format.md; the built-in room is `scenes/tncg15.toml`.
//!
//! A table with a `type` (a material, a shape, a light) is read as that
//! type's own struct, defined beside the code that builds it
//! ([`defs::Entry`]): a new field of a type is a line of its struct, a new
//! type a struct and an arm of its section's `match`.
//!
//! Every value is read with its byte span, so a mistake is reported as
//! `file:line:column: field: what is wrong` ([`locate`]), whether the TOML
//! parser found it (a syntax error), serde (a type, an unknown or missing
//! field) or the checks of [`build`] (a negative radius, a material that
//! does not exist, an OBJ file that cannot be read).

mod bsdf;
mod build;
mod camera;
mod defs;
mod light;
mod locate;
mod material;
mod medium;
mod read;
mod shape;
mod texture;

use super::SceneParts;
use locate::Source;
pub use read::{read_scene_text, MAX_SCENE_BYTES};
use std::path::{Path, PathBuf};

/// A mistake in a scene file, located.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}:{column}: {field}: {message}", path.display())]
pub struct SceneError {
    pub path: PathBuf,
    pub line: usize,
    pub column: usize,
    /// Where in the scene's structure, e.g. `shapes[2].radius`.
    pub field: String,
    pub message: String,
}

/// Where a part of the scene is written in its file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Place {
    pub line: usize,
    pub column: usize,
    /// Its path in the scene's structure, e.g. `materials.glass`.
    pub field: String,
}

/// The places of a scene file's parts, for what is said of them after the
/// file has been read (the Mitsuba export's refusals).
#[derive(Debug, Clone, Default)]
pub struct Origins {
    pub path: PathBuf,
    pub camera: Place,
    /// Per material of the scene's parts, by index.
    pub materials: Vec<Place>,
    /// Per light of the scene's parts, by index (an emissive shape's
    /// triangles each name the shape).
    pub lights: Vec<Place>,
    /// Per object (a `[[shapes]]` entry), by index.
    pub objects: Vec<Place>,
}

impl Origins {
    /// A message about the part written at `place`.
    pub fn error(&self, place: &Place, message: impl Into<String>) -> SceneError {
        SceneError {
            path: self.path.clone(),
            line: place.line,
            column: place.column,
            field: place.field.clone(),
            message: message.into(),
        }
    }
}

/// A scene read from a file, with what only the Whitted program uses.
#[derive(Debug, Clone)]
pub struct SceneFile {
    pub parts: SceneParts,
    /// Where each part is written.
    pub origins: Origins,
    /// The n of the n x n jittered samples per pixel.
    pub rays_per_pixel_edge: u32,
    /// Whitted-only features that a physically based renderer cannot
    /// honour (ambient light, a falloff other than 1/d^2, a Phong material
    /// that creates energy), located.
    pub not_physical: Vec<SceneError>,
    /// The OBJ files it reads.
    pub meshes: Vec<PathBuf>,
}

/// Reads and checks a scene file. Relative OBJ paths are relative to the
/// scene file's folder.
pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
    parse(&read_scene_text(path)?, path)
}

/// Parses scene text as if read from `path` (used for messages and to find
/// OBJ files next to it).
pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    let line_starts = locate::line_starts(text);
    let src = Source { path, text, line_starts: &line_starts };
    build::build(src, defs::FileDef::read(&src)?)
}
