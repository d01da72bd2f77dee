//! The Mitsuba 3 scene front-end: a scene in Mitsuba's XML format (versions
//! 2 and 3, as Mitsuba 3 and Blender's Mitsuba exporter write it) read into
//! the same [`SceneParts`] the TOML front-end builds, so that nothing past
//! this module knows which format a scene came from.
//!
//! Reading is in three steps: [`xml`] reads the files (includes, defaults,
//! `$parameters`, search paths), [`props`] gives each plugin its typed
//! parameters and refuses any it did not ask for, and the builders here
//! (sensor, shapes, BSDFs, emitters) turn plugins into the scene. Mitsuba's
//! conventions are converted once, here: its spectra into RGB as its RGB
//! variants do ([`spectrum`]), its camera frame and film into the course's
//! image plane, its one-sided BSDFs into a black back face.
//!
//! A plugin or a parameter photonmap does not support is an error at its
//! file, line and column naming what is supported; with
//! [`Options::substitute`] an unsupported BSDF becomes a grey diffuse one
//! and an unsupported emitter is left out, each listed in
//! [`Imported::substitutions`].

pub mod cie;
mod emitters;
mod film;
mod materials;
mod media;
mod principled;
pub mod props;
mod sensor;
mod shapes;
pub mod spectrum;
mod textures;
pub mod xml;

use super::file::{Origins, Place, SceneError, SceneFile};
use super::{Prim, SceneParts};
use crate::camera::Camera;
use crate::material::Material;
use crate::math::Color;
use glam::Vec3;
use props::{Ids, Plugin};
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Where an element is written.
#[derive(Debug, Clone, PartialEq)]
pub struct Loc {
    pub file: Rc<Path>,
    pub line: usize,
    pub column: usize,
}

/// How to read a scene.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// `-D name=value`: parameters that win over the file's `<default>`s.
    pub defines: Vec<(String, String)>,
    /// Render anyway where a BSDF or emitter is not supported, with a
    /// stated stand-in.
    pub substitute: bool,
}

/// A Mitsuba scene, read.
#[derive(Debug, Clone)]
pub struct Imported {
    pub file: SceneFile,
    /// The sampler's samples per pixel.
    pub spp: u32,
    /// Each stand-in used under [`Options::substitute`], located.
    pub substitutions: Vec<String>,
    /// Every file read: the XML files, then meshes and textures.
    pub inputs: Vec<PathBuf>,
    /// Why photon mapping cannot render the scene's path limit (a
    /// `max_depth` of 3 or more: the photon maps hold paths of every
    /// length), located; the path tracer can.
    pub photon_limit: Option<SceneError>,
}

/// Reads a Mitsuba XML scene.
pub fn load(path: &Path, options: &Options) -> Result<Imported, SceneError> {
    let doc = xml::read(path, &options.defines)?;
    let mut ids = Ids::new();
    props::collect_ids(&doc.root, &mut ids)?;
    let mut b = Builder {
        search: doc.search,
        options,
        materials: Vec::new(),
        one_sided: Vec::new(),
        material_cache: Vec::new(),
        prims: Vec::new(),
        shading_normals: Vec::new(),
        lights: Vec::new(),
        origins: Origins { path: path.to_path_buf(), ..Default::default() },
        inputs: doc.files,
        substitutions: Vec::new(),
        objects: 0,
        max_depth: None,
        hide_emitters: false,
        depth_place: None,
        textures: Vec::new(),
        texture_cache: Vec::new(),
        textured: Vec::new(),
        surfaces: Vec::new(),
        frames: Vec::new(),
        perturb: Vec::new(),
        light_patterns: Vec::new(),
        bsdf_nesting: 0,
        media: Default::default(),
    };
    let mut camera: Option<(Camera, u32, f64, Plugin)> = None;
    let mut integrator_seen = false;
    for el in &doc.root.children {
        match el.tag.as_str() {
            "shape" => b.shape(&Plugin::new(el, &ids)?, glam::DAffine3::IDENTITY)?,
            "emitter" => b.emitter(&Plugin::new(el, &ids)?)?,
            "sensor" => {
                let p = Plugin::new(el, &ids)?;
                if camera.is_some() {
                    return Err(p.refuse("photonmap renders one sensor; this scene has a second"));
                }
                b.sensor_medium(&p)?;
                let (c, spp, far) = sensor::camera(&p)?;
                b.origins.camera = place(&p);
                camera = Some((c, spp, far, p));
            }
            "integrator" => {
                let p = Plugin::new(el, &ids)?;
                if integrator_seen {
                    return Err(p.refuse("a scene has one integrator; this is a second"));
                }
                integrator_seen = true;
                b.integrator(&p)?;
            }
            // Declared for reference elsewhere: read where used.
            "bsdf" | "texture" | "spectrum" | "medium" | "phase" | "volume" => {
                if el.attr("id").is_none() {
                    return Err(xml::error(&el.loc, &el.tag, format!("a top-level <{}> needs an id", el.tag)));
                }
            }
            t => {
                return Err(xml::error(
                    &el.loc,
                    t,
                    format!(
                    "<{t}> is not a scene element photonmap reads (shape, bsdf, emitter, sensor, integrator, texture, \
                     medium, phase, volume)"
                ),
                ))
            }
        }
    }
    let Some((camera, spp, far, sensor)) = camera else {
        return Err(xml::error(&doc.root.loc, "scene", "the scene has no <sensor>"));
    };
    // Far clipping is not implemented: it must cut nothing.
    let farthest = b.prims.iter().fold(0.0f64, |d, p| {
        let (lo, hi) = p.shape.bounds();
        let corner = (lo - camera.eye).abs().max((hi - camera.eye).abs());
        d.max(corner.as_dvec3().length())
    });
    if farthest > far {
        return Err(sensor.fail(
            sensor.loc(),
            "far_clip",
            format!(
                "the scene reaches {farthest:.4e} from the eye, beyond where the camera's rays end ({far}: far_clip, \
                 less near_clip for an orthographic sensor): photonmap does not clip far geometry"
            ),
        ));
    }
    let texturing = b.texturing();
    let media = b.media_parts();
    let parts = SceneParts {
        prims: b.prims,
        shading_normals: b.shading_normals,
        materials: b.materials,
        lights: b.lights,
        ambient: Color::ZERO,
        camera,
        one_sided: b.one_sided,
        paths: super::PathLimits { max_depth: b.max_depth, hide_emitters: b.hide_emitters },
        texturing,
        media,
    };
    let file = SceneFile {
        parts,
        origins: b.origins,
        rays_per_pixel_edge: 1,
        not_physical: Vec::new(),
        meshes: b.inputs.iter().skip(1).cloned().collect(),
    };
    let photon_limit = match (b.max_depth, &b.depth_place) {
        (Some(d), Some(loc)) if d >= 3 => Some(xml::error(
            loc,
            "integrator.max_depth",
            format!(
                "photon mapping renders paths of every length and cannot stop them at max_depth {d}; \
                 render with --integrator path (exact), or with --substitute (every length)"
            ),
        )),
        _ => None,
    };
    Ok(Imported { file, spp, substitutions: b.substitutions, inputs: b.inputs, photon_limit })
}

/// `d` as a unit vector in single precision: as written where that is
/// unit already (to its last bits), so that a direction photonmap
/// normalised and exported reads back the same bits; else normalised.
fn unit(d: glam::DVec3) -> Option<glam::Vec3> {
    let v = d.as_vec3();
    if v.is_finite() && (v.length_squared() - 1.0).abs() <= 4.0 * f32::EPSILON {
        return Some(v);
    }
    d.try_normalize().map(|n| n.as_vec3())
}

fn place(p: &Plugin) -> Place {
    Place { line: p.loc().line, column: p.loc().column, field: format!("{} '{}'", p.el.tag, p.kind) }
}

/// What the scene is being built into.
struct Builder<'a> {
    search: Vec<PathBuf>,
    options: &'a Options,
    materials: Vec<Material>,
    one_sided: Vec<bool>,
    /// Materials already built from a BSDF element (by its address), so
    /// that a BSDF shared by reference is one material.
    material_cache: Vec<(*const xml::Element, u32)>,
    prims: Vec<Prim>,
    shading_normals: Vec<[Vec3; 3]>,
    lights: Vec<crate::light::Light>,
    origins: Origins,
    inputs: Vec<PathBuf>,
    substitutions: Vec<String>,
    objects: u32,
    max_depth: Option<u32>,
    hide_emitters: bool,
    /// Where max_depth was given.
    depth_place: Option<Loc>,
    textures: Vec<textures::Draft>,
    texture_cache: Vec<(*const xml::Element, u32)>,
    /// Per material, its recipe where it reads textures.
    textured: Vec<Option<crate::material::Textured>>,
    /// Per primitive, where textures are read on it.
    surfaces: Vec<crate::texture::SurfaceUv>,
    frames: Vec<glam::Affine3A>,
    /// Per material, the normal or bump map it is seen through.
    perturb: Vec<Option<crate::texture::Perturb>>,
    /// Per light, the image over a triangle light.
    light_patterns: Vec<Option<std::sync::Arc<crate::light::AreaPattern>>>,
    /// How deep the BSDF being read is nested in others (a BSDF that
    /// refers to itself would nest without end).
    bsdf_nesting: u32,
    media: media::MediaDraft,
}

impl Builder<'_> {
    /// A file named in the scene: relative to the scene's search path
    /// (`<path>` folders, then the scene file's folder), as Mitsuba's
    /// file resolver looks it up.
    fn resolve(&mut self, name: &str, from: &Loc) -> Result<PathBuf, SceneError> {
        let p = Path::new(name);
        let mut tried = Vec::new();
        if p.is_absolute() {
            tried.push(p.to_path_buf());
        } else {
            for dir in self.search.iter().rev() {
                tried.push(dir.join(p));
            }
            tried.push(from.file.parent().unwrap_or(Path::new(".")).join(p));
            // Mitsuba's resolver holds the first scene file's folder too:
            // a file named in an included file may be beside the scene.
            if let Some(main) = self.inputs.first().and_then(|f| f.parent()) {
                let beside = main.join(p);
                if !tried.contains(&beside) {
                    tried.push(beside);
                }
            }
        }
        match tried.iter().find(|t| t.is_file()) {
            Some(found) => {
                self.inputs.push(found.clone());
                Ok(found.clone())
            }
            None => Err(xml::error(
                from,
                "filename",
                format!(
                    "cannot find '{name}' (looked in {})",
                    tried.iter().map(|t| t.display().to_string()).collect::<Vec<_>>().join(", ")
                ),
            )),
        }
    }

    /// The `<integrator>`: photonmap is the renderer, but the path length
    /// and whether lights are seen directly are the scene's.
    fn integrator(&mut self, p: &Plugin) -> Result<(), SceneError> {
        match p.kind {
            // Wrappers that change what is written, not what is rendered.
            "moment" | "aov" => {
                let inner = p.objects("integrator")?;
                p.finish("a nested <integrator>")?;
                for i in &inner {
                    self.integrator(i)?;
                }
                Ok(())
            }
            "direct" => {
                for n in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                    p.integer(n)?;
                }
                self.hide_emitters = p.boolean("hide_emitters", false)?;
                self.max_depth = Some(2);
                p.finish("emitter_samples, bsdf_samples, shading_samples, hide_emitters")
            }
            "path" | "volpath" | "volpathmis" | "ptracer" | "prb" => {
                let depth = p.integer("max_depth")?.unwrap_or(-1);
                self.depth_place = Some(p.loc().clone());
                // Russian roulette changes the noise, not the expected image.
                p.integer("rr_depth")?;
                self.hide_emitters = p.boolean("hide_emitters", false)?;
                if p.kind == "ptracer" {
                    p.integer("samples_per_pass")?;
                }
                self.max_depth = match depth {
                    -1 => None,
                    d if d >= 0 => Some(d as u32),
                    d => return Err(p.fail(p.loc(), "max_depth", format!("must be -1 or >= 0, got {d}"))),
                };
                p.finish("max_depth, rr_depth, hide_emitters, samples_per_pass (ptracer)")
            }
            k => Err(p.refuse(format!(
                "the integrator '{k}' is not one photonmap can stand in for (path, volpath, ptracer, direct, moment)"
            ))),
        }
    }

    fn new_object(&mut self) -> u32 {
        self.objects += 1;
        self.objects - 1
    }

    fn substitute(&mut self, p: &Plugin, what: &str, err: SceneError) -> Result<(), SceneError> {
        if !self.options.substitute {
            return Err(err);
        }
        self.substitutions.push(format!(
            "{}:{}:{}: {what} ({})",
            err.path.display(),
            err.line,
            err.column,
            err.message
        ));
        let _ = p;
        Ok(())
    }
}
