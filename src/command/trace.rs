//! `trace SCENE OUT [DEPTH]`: the CS475 Whitted ray tracer's render of a
//! scene file (notes/scene-format.md), written as PNG/PPM (8-bit, clamped)
//! or EXR.

use crate::error::Error;
use crate::film::ToneMap;
use crate::math::Color;
use crate::memory::available_memory;
use crate::output::{check_writable, same_file, write_with, Extras};
use crate::progress::{Mode, Wait};
use crate::provenance::SceneId;
use crate::render::settings::Settings;
use crate::render::tracers::WhittedTracing;
use crate::render::{render_with, Method};
use crate::scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

/// A Whitted render as the command line asks it.
pub struct Request {
    pub scene: PathBuf,
    pub out: PathBuf,
    /// Reflections stop after this many bounces.
    pub depth: u32,
    /// None: the scene file's.
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub spp: Option<u32>,
    pub seed: u64,
    pub quiet: bool,
}

pub fn run(cli: Request) -> Result<(), Error> {
    let start = Instant::now();
    check_writable(&cli.out)?;
    let size = std::fs::metadata(&cli.scene).map_or(String::new(), |m| format!(" ({:.1} MB)", m.len() as f64 / 1e6));
    let wait = Wait::start(Mode::detect(cli.quiet), format!("trace: loading {}{size}", cli.scene.display()));
    let file = crate::scene::file::load(&cli.scene).map_err(|e| Error::Invalid(e.to_string()))?;
    if !file.parts.media.media.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: the scene has participating media, which the Whitted tracer does not render (photonmap does)",
            cli.scene.display()
        )));
    }
    refuse_unreadable(&file)?;
    let id =
        SceneId::from_files(&cli.scene, &file.meshes).map_err(|e| Error::Io { path: cli.scene.clone(), source: e })?;
    for input in &id.inputs {
        if same_file(&cli.out, input) {
            return Err(Error::Invalid(format!(
                "{}: the output is also an input of the scene; it would be overwritten (choose another name)",
                cli.out.display()
            )));
        }
    }
    let n = file.rays_per_pixel_edge;
    let mut scene = Scene::from_parts(file.parts);
    wait.finish();
    let load_time = start.elapsed();
    let (w, h) = (cli.width.unwrap_or(scene.camera.width), cli.height.unwrap_or(scene.camera.height));
    scene.camera = scene.camera.fit(w, h).map_err(|e| Error::Invalid(format!("{}: {e}", cli.scene.display())))?;
    let spp = cli.spp.unwrap_or(n * n);
    // The film (12 bytes a pixel) and its 8-bit copy must fit.
    let need = w as u64 * h as u64 * 16;
    if available_memory().is_some_and(|available| need > available) {
        return Err(Error::Invalid(format!(
            "{}: a {w} x {h} image needs about {:.1} GB; less memory is available",
            cli.scene.display(),
            need as f64 / 1e9
        )));
    }
    if scene.lights.is_empty() && scene.ambient == Color::ZERO {
        return Err(Error::Invalid(format!(
            "{}: the scene has no light (a [[lights]] entry, an emissive shape or ambient), so its image is black",
            cli.scene.display()
        )));
    }
    let t = Instant::now();
    let settings =
        Settings { method: Method::Whitted, width: w, height: h, spp, seed: cli.seed, ..Settings::default() };
    let tracer = WhittedTracing { max_depth: cli.depth };
    let (film, _) = render_with(&scene, &settings, &tracer, Mode::detect(cli.quiet));
    let render_time = t.elapsed();
    let attributes = [
        ("scene", id.name.clone()),
        ("scene_sha256", id.hash.clone()),
        ("integrator", Method::Whitted.name().to_string()),
        ("seed", cli.seed.to_string()),
        ("spp", spp.to_string()),
        ("depth", cli.depth.to_string()),
        ("wall_seconds", format!("{:.3}", start.elapsed().as_secs_f64())),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    let t = Instant::now();
    write_with(&cli.out, &film, ToneMap::Clamp, 1.0, &Extras { attributes, layers: Vec::new() })?;
    let write_time = t.elapsed();
    if !cli.quiet {
        let threads = rayon::current_num_threads();
        let threads = crate::stats::counted(threads as u64, "thread", "threads");
        eprintln!("trace: Whitted, {w} x {h}, {spp} spp, depth {}, {threads}", cli.depth);
        eprintln!(
            "  scene load   {:>8.3} s  {} primitives, {} lights",
            load_time.as_secs_f64(),
            scene.prim_count(),
            scene.lights.len()
        );
        eprintln!("  camera pass  {:>8.3} s", render_time.as_secs_f64());
        eprintln!("  write        {:>8.3} s  {}", write_time.as_secs_f64(), cli.out.display());
        eprintln!("  total        {:>8.3} s", start.elapsed().as_secs_f64());
    }
    Ok(())
}

/// Refuses, at its place in the file, the first material on a shape that
/// the course's tracer cannot render (it reads Phong, Lambertian as Phong,
/// and follows the perfect mirrors and refractions): a rough, coated,
/// principled, blended, masked or textured one would be drawn as something
/// else without a word.
fn refuse_unreadable(file: &crate::scene::file::SceneFile) -> Result<(), Error> {
    let parts = &file.parts;
    let texturing = &parts.texturing;
    for p in &parts.prims {
        let m = p.material as usize;
        let material = &parts.materials[m];
        let readable = material.course_phong().is_some()
            || material.is_specular()
            || matches!(material, crate::material::Material::Masked(k) if k.opacity == 0.0);
        let textured =
            matches!(texturing.materials.get(m), Some(Some(_))) || matches!(texturing.perturb.get(m), Some(Some(_)));
        if readable && !textured {
            continue;
        }
        let place = file.origins.materials.get(m).cloned().unwrap_or_default();
        return Err(Error::Invalid(
            file.origins
                .error(
                    &place,
                    "the Whitted tracer renders lambertian, phong, mirror, glass, conductor, thindielectric and null \
                     materials without textures; this material only photonmap renders",
                )
                .to_string(),
        ));
    }
    Ok(())
}
