//! The scene a render asks for: the built-in room, photonmap's TOML or
//! Mitsuba 3's XML, with what it is (its files' hash) and the method it
//! needs.

use super::render::Request;
use crate::error::Error;
use crate::progress::{Mode, Wait};
use crate::provenance::SceneId;
use crate::render::Method;
use crate::scene::{mitsuba, Eye, Scene};
use std::path::Path;

/// A scene loaded for a render.
pub struct Loaded {
    pub scene: Scene,
    /// Its samples per pixel (a scene file's rays_per_pixel_edge squared).
    pub spp: u32,
    pub id: SceneId,
    /// The method asked, or the one the scene needs.
    pub method: Method,
}

/// Loads the scene of `req`; a load that takes long is said.
pub fn load(req: &Request) -> Result<Loaded, Error> {
    let wait = Wait::start(Mode::detect(req.quiet), loading_line(req.scene.as_deref()));
    let mut method = req.method.unwrap_or(Method::Photon);
    let (scene, spp, id) = match &req.scene {
        None => {
            let name = format!("built-in TNCG15 room, eye {}", if req.eye == Eye::Two { 2 } else { 1 });
            (Scene::tncg15(req.eye), 4, SceneId::built_in(&name))
        }
        Some(path) if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("xml")) => {
            let options = mitsuba::Options { defines: req.defines.clone(), substitute: req.substitute };
            let mut imported = mitsuba::load(path, &options).map_err(|e| Error::Invalid(e.to_string()))?;
            match (imported.photon_limit.take(), req.method) {
                (Some(e), Some(Method::Photon)) => {
                    if !req.substitute {
                        return Err(Error::Invalid(e.to_string()));
                    }
                    imported.substitutions.push(format!("{e} (rendered with paths of every length)"));
                    imported.file.parts.paths.max_depth = None;
                }
                (Some(_), None) => {
                    method = Method::Path;
                    if !req.quiet {
                        let depth = imported.file.parts.paths.max_depth.unwrap_or(0);
                        eprintln!(
                            "photonmap: {}: the integrator's max_depth {depth} stops paths at {depth} vertices, which \
                             the path tracer does exactly and photon mapping cannot: rendering with --integrator path",
                            path.display()
                        );
                    }
                }
                _ => {}
            }
            for s in &imported.substitutions {
                eprintln!("substituted: {s}");
            }
            let mut id = SceneId::from_files(path, &imported.inputs[1..])
                .map_err(|e| Error::Io { path: path.clone(), source: e })?;
            id.substitutions = imported.substitutions;
            (Scene::from_parts(imported.file.parts), imported.spp, id)
        }
        Some(path) => {
            if !req.defines.is_empty() || req.substitute {
                return Err(Error::Invalid(format!(
                    "{}: -D and --substitute are for Mitsuba scenes (.xml)",
                    path.display()
                )));
            }
            let file = crate::scene::file::load(path).map_err(|e| Error::Invalid(e.to_string()))?;
            if !file.not_physical.is_empty() {
                let all: Vec<String> = file.not_physical.iter().map(|e| e.to_string()).collect();
                return Err(Error::Invalid(format!(
                    "{}\n(the `trace` program renders this scene; photonmap cannot honour these)",
                    all.join("\n")
                )));
            }
            let id =
                SceneId::from_files(path, &file.meshes).map_err(|e| Error::Io { path: path.clone(), source: e })?;
            let n = file.rays_per_pixel_edge;
            (Scene::from_parts(file.parts), n * n, id)
        }
    };
    wait.finish();
    if scene.media().is_some() && method == Method::Photon && req.method.is_none() {
        // Without a method asked, a scene with media is path traced: the
        // unbiased estimate Mitsuba's acceptance test measures its scenes
        // with (volumetric photon mapping is asked for by name).
        method = Method::Path;
        if !req.quiet {
            eprintln!(
                "photonmap: {}: the scene has participating media: rendering with --integrator path \
                 (--integrator photon for volumetric photon mapping)",
                id.name
            );
        }
    }
    Ok(Loaded { scene, spp, id, method })
}

/// What a long load says: the scene file and its size.
pub fn loading_line(scene: Option<&Path>) -> String {
    match scene {
        Some(path) => {
            let size = std::fs::metadata(path).map_or(String::new(), |m| format!(" ({:.1} MB)", m.len() as f64 / 1e6));
            format!("photonmap: loading {}{size}", path.display())
        }
        None => "photonmap: building the built-in room".into(),
    }
}
