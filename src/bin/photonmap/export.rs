//! `photonmap export --mitsuba [SCENE.toml] OUT.xml`: the scene written for
//! Mitsuba 3 (photonmap::export::mitsuba), its meshes beside it.

use photonmap::error::Error;
use photonmap::export::mitsuba::{to_mitsuba, Placement};
use photonmap::output::same_file;
use photonmap::output::write_bytes;
use photonmap::scene::{Eye, Scene};
use std::path::PathBuf;

/// Writes the scene (a scene file, or the built-in room) as a Mitsuba 3
/// scene: OUT.xml and its meshes in OUT-meshes/. What Mitsuba has no
/// faithful equivalent for is refused, with its place in the file.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example: photonmap export --mitsuba scenes/suite/02-cornell.toml cornell.xml\n\
                        Render it: python3 -c \"import mitsuba as mi; mi.set_variant('scalar_rgb'); \
                        mi.Bitmap(mi.render(mi.load_file('cornell.xml', spp=64))).write('cornell.exr')\"")]
pub struct Args {
    /// Write for Mitsuba 3 (the one format there is).
    #[arg(long, required = true)]
    mitsuba: bool,
    /// The scene file (omit it for the built-in room), then the XML to write.
    #[arg(value_name = "[SCENE.toml] OUT.xml", num_args = 1..=2, required = true)]
    paths: Vec<PathBuf>,
    /// Built-in room: eye 1 = (-2,0,0), 2 = (-1,0,0).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    eye: Option<u8>,
    /// The point of the scene written as Mitsuba's origin [default: the
    /// camera's eye]. Mitsuba offsets a ray leaving a surface by a length
    /// that grows with the distance from its origin: for a reference that
    /// resolves a small glass object or a sharp shadow, give its centre
    /// here.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point, allow_hyphen_values = true)]
    origin: Option<glam::Vec3>,
    /// Mitsuba's units per scene unit (the image is the same); with
    /// --origin, a large scale makes the ray offsets a fixed fraction of
    /// the distance from the origin.
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
}

fn parse_point(text: &str) -> Result<glam::Vec3, String> {
    let v: Vec<f32> = text
        .split(',')
        .map(|c| c.trim().parse::<f32>().map_err(|e| format!("{c:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(glam::Vec3::new(*x, *y, *z)),
        _ => Err("give three finite numbers, X,Y,Z".into()),
    }
}

pub fn run(args: Args) -> Result<(), Error> {
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
        if same_file(scene, &out) {
            return Err(Error::Invalid(format!("{}: that is the scene being exported", out.display())));
        }
    }
    let file = match &scene {
        Some(path) => Some(photonmap::scene::file::load(path).map_err(|e| Error::Invalid(e.to_string()))?),
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
