//! `photonmap export --mitsuba [SCENE.toml] OUT.xml`: the scene written for
//! Mitsuba 3 (`crate::export::mitsuba`), its meshes beside it.

use crate::error::Error;
use crate::export::mitsuba::{to_mitsuba, Placement};
use crate::output::{same_file, write_bytes};
use crate::scene::{Eye, Scene};
use std::path::PathBuf;

/// An export as the command line asks it.
pub struct Request {
    /// [SCENE.toml] OUT.xml.
    pub paths: Vec<PathBuf>,
    /// The built-in room's eye (1 or 2).
    pub eye: Option<u8>,
    /// The point written as Mitsuba's origin, and Mitsuba's units per
    /// scene unit.
    pub origin: Option<glam::Vec3>,
    pub scale: f32,
}

/// Writes the scene as Mitsuba 3's.
pub fn run(args: Request) -> Result<(), Error> {
    let (scene, out) = match args.paths.as_slice() {
        [out] => (None, out.clone()),
        [scene, out] => (Some(scene.clone()), out.clone()),
        _ => return Err(Error::Invalid("export: give [SCENE.toml] OUT.xml".into())),
    };
    if out.extension().and_then(|e| e.to_str()) != Some("xml") {
        return Err(Error::Invalid(format!("{}: the Mitsuba scene is written as .xml", out.display())));
    }
    if let Some(scene) = &scene {
        if args.eye.is_some() {
            return Err(Error::Invalid("--eye chooses the built-in room's eye; a scene file has its camera".into()));
        }
        // A Mitsuba scene read as TOML fails on its first tag with a TOML
        // parser's message; say what the command reads instead.
        if scene.extension().is_some_and(|e| e.eq_ignore_ascii_case("xml")) {
            return Err(Error::Invalid(format!(
                "{}: export writes photonmap's TOML scenes (.toml) as Mitsuba's; this one is Mitsuba's already",
                scene.display()
            )));
        }
        if same_file(scene, &out) {
            return Err(Error::Invalid(format!("{}: that is the scene being exported", out.display())));
        }
    }
    let file = match &scene {
        Some(path) => Some(crate::scene::file::load(path).map_err(|e| Error::Invalid(e.to_string()))?),
        None => None,
    };
    let (parts, origins) = match file {
        Some(f) => (f.parts, Some(f.origins)),
        None => (Scene::tncg15_parts(if args.eye == Some(2) { Eye::Two } else { Eye::One }), None),
    };
    let stem = out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let mesh_dir = format!("{stem}-meshes");
    let placement = Placement::new(args.origin.unwrap_or(parts.camera.eye), args.scale)
        .map_err(|m| Error::Invalid(format!("export: {m}")))?;
    let exported = to_mitsuba(&parts, origins.as_ref(), &mesh_dir, placement)
        .map_err(|r| Error::Invalid(r.describe(origins.as_ref())))?;
    let dir = out.parent().filter(|p| !p.as_os_str().is_empty()).map(PathBuf::from).unwrap_or_else(|| ".".into());
    // As for a render's outputs, a missing directory is a mistake to say,
    // not one to make.
    if !dir.is_dir() {
        return Err(Error::Invalid(format!("{}: the directory {} does not exist", out.display(), dir.display())));
    }
    // The mesh files are named by the export, not by the user: one already
    // there is replaced only by the same bytes (the same scene exported
    // again), never by another scene's mesh.
    for (name, bytes) in &exported.meshes {
        let path = dir.join(name);
        if path.exists() && std::fs::read(&path).ok().as_deref() != Some(bytes.as_slice()) {
            return Err(Error::Invalid(format!(
                "{}: a mesh file is already there, with other contents; it is not replaced (remove {} or \
                 choose another name for {})",
                path.display(),
                dir.join(&mesh_dir).display(),
                out.display()
            )));
        }
    }
    if !exported.meshes.is_empty() {
        let meshes = dir.join(&mesh_dir);
        if !meshes.is_dir() {
            std::fs::create_dir(&meshes).map_err(|e| Error::Io { path: meshes.clone(), source: e })?;
        }
    }
    for (name, bytes) in &exported.meshes {
        write_bytes(&dir.join(name), bytes)?;
    }
    write_bytes(&out, exported.xml.as_bytes())?;
    for note in &exported.notes {
        eprintln!("photonmap: note: {note}");
    }
    eprintln!(
        "photonmap: wrote {} and {} meshes in {}",
        out.display(),
        exported.meshes.len(),
        dir.join(&mesh_dir).display()
    );
    Ok(())
}
