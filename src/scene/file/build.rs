//! A scene file's structure checked and turned into [`SceneParts`]: every
//! value in range, every name defined, every field one its type uses.

use super::defs::*;
use super::locate::Source;
use super::{SceneError, SceneFile};
use crate::material::Material;
use crate::math::Color;
use crate::scene::{Prim, SceneParts};
use glam::Vec3;
use std::collections::BTreeMap;
use std::ops::Range;
use toml::Spanned;

/// Builds the scene from its checked structure.
pub fn build<'i>(src: Source<'i>, def: FileDef<'i>) -> Result<SceneFile, SceneError> {
    Builder {
        src,
        materials: Vec::new(),
        names: BTreeMap::new(),
        prims: Vec::new(),
        shading_normals: Vec::new(),
        lights: Vec::new(),
        not_physical: Vec::new(),
        meshes: Vec::new(),
        origins: super::Origins { path: src.path.to_path_buf(), ..Default::default() },
        media: Default::default(),
        textured: Vec::new(),
        one_sided: Vec::new(),
        perturb: Vec::new(),
        pending: BTreeMap::new(),
        defining: Vec::new(),
        textures: Vec::new(),
        texture_names: BTreeMap::new(),
        pending_textures: BTreeMap::new(),
        surfaces: Vec::new(),
        frames: Vec::new(),
        attribute_textures: Vec::new(),
        mesh_attributes: BTreeMap::new(),
    }
    .build(def)
}

pub(super) struct Builder<'a> {
    pub(super) src: Source<'a>,
    pub(super) materials: Vec<Material>,
    pub(super) names: BTreeMap<String, u32>,
    pub(super) prims: Vec<Prim>,
    pub(super) shading_normals: Vec<[Vec3; 3]>,
    pub(super) lights: Vec<crate::light::Light>,
    pub(super) not_physical: Vec<SceneError>,
    pub(super) meshes: Vec<std::path::PathBuf>,
    pub(super) origins: super::Origins,
    pub(super) media: super::medium::MediaDraft,
    /// Per material: its recipe where it reads textures, whether it is
    /// one-sided, its normal or bump map.
    pub(super) textured: Vec<Option<crate::material::Textured>>,
    pub(super) one_sided: Vec<bool>,
    pub(super) perturb: Vec<Option<crate::texture::Perturb>>,
    /// The named materials not built yet, and those being built (a
    /// material nested by name is built where it is first named).
    pub(super) pending: BTreeMap<String, Entry<'a>>,
    pub(super) defining: Vec<String>,
    pub(super) textures: Vec<crate::texture::Texture>,
    pub(super) texture_names: BTreeMap<String, u32>,
    pub(super) pending_textures: BTreeMap<String, Entry<'a>>,
    /// Per primitive, its texture coordinates (where it has any besides
    /// its barycentrics), and the analytic shapes' frames they name.
    pub(super) surfaces: Vec<crate::texture::SurfaceUv>,
    pub(super) frames: Vec<glam::Affine3A>,
    /// The `mesh_attribute` textures (index, attribute, scale), filled
    /// once every mesh is read, from the meshes' attributes by name: per
    /// primitive, its three corners' values.
    pub(super) attribute_textures: Vec<(u32, String, f32)>,
    pub(super) mesh_attributes: BTreeMap<String, Vec<(usize, [Color; 3])>>,
}

/// A value with its span and its place in the file, for checks.
pub(super) struct At<'v, T> {
    pub(super) value: &'v T,
    pub(super) span: Range<usize>,
    pub(super) field: String,
}

pub(super) fn at<'v, T>(s: &'v Spanned<T>, field: String) -> At<'v, T> {
    At { value: s.get_ref(), span: s.span(), field }
}

/// The largest coordinate, colour or length a scene file may hold: beyond
/// it, squared distances and sums of photon powers overflow single
/// precision inside the renderer and light would vanish without a word.
pub const LIMIT: f32 = 1e15;

/// The most power (W) a scene's lights may emit in all: photon powers and
/// pixel sums are accumulated in single precision (at most 3.4e38) and
/// divided by small areas in density estimates.
pub const MAX_POWER: f64 = 1e30;

impl<'a> Builder<'a> {
    pub(super) fn fail<T>(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> Result<T, SceneError> {
        Err(self.src.error(span, field, message))
    }

    pub(super) fn finite(&self, v: &At<V3>) -> Result<Vec3, SceneError> {
        let x = Vec3::from_array(*v.value);
        if !x.is_finite() {
            return self.fail(v.span.clone(), &v.field, format!("must be finite, got {x}"));
        }
        if x.abs().max_element() > LIMIT {
            return self.fail(
                v.span.clone(),
                &v.field,
                format!(
                    "must be within ±{LIMIT:e} (larger values overflow single precision inside the renderer; \
                     scale the scene or its light down), got [{:e}, {:e}, {:e}]",
                    x.x, x.y, x.z
                ),
            );
        }
        Ok(x)
    }

    pub(super) fn color(&self, v: &At<V3>) -> Result<Color, SceneError> {
        let c = self.finite(v)?;
        if c.min_element() < 0.0 {
            return self.fail(v.span.clone(), &v.field, format!("must not be negative, got {c}"));
        }
        Ok(c)
    }

    pub(super) fn direction(&self, v: &At<V3>) -> Result<Vec3, SceneError> {
        let d = self.finite(v)?;
        d.try_normalize().ok_or_else(|| self.src.error(v.span.clone(), &v.field, "must not be the zero vector"))
    }

    pub(super) fn number(&self, v: &At<f32>, lo: f32, hi: f32, open_lo: bool) -> Result<f32, SceneError> {
        let x = *v.value;
        let hi = hi.min(LIMIT);
        let ok = x.is_finite() && x <= hi && if open_lo { x > lo } else { x >= lo };
        if !ok {
            let range = match (open_lo, hi == LIMIT) {
                (true, true) => format!("must be > {lo} and at most {LIMIT:e}"),
                (false, true) => format!("must be >= {lo} and at most {LIMIT:e}"),
                (true, false) => format!("must be in ({lo}, {hi}]"),
                (false, false) => format!("must be in [{lo}, {hi}]"),
            };
            return self.fail(v.span.clone(), &v.field, format!("{range}, got {x}"));
        }
        Ok(x)
    }

    fn build(mut self, def: FileDef<'a>) -> Result<SceneFile, SceneError> {
        self.pending_textures = def.textures;
        let names: Vec<String> = def.materials.keys().cloned().collect();
        self.pending = def.materials;
        for name in names {
            self.define_material(&name)?;
        }
        // Textures no material names are read all the same (a missing
        // file is a mistake wherever it is written).
        let textures: Vec<String> = self.pending_textures.keys().cloned().collect();
        for name in textures {
            self.define_texture(&name)?;
        }
        for (name, m) in def.media {
            self.medium(name, m)?;
        }
        for (i, mut s) in def.shapes.into_iter().enumerate() {
            let place = self.place(s.kind.span(), format!("shapes[{i}]"));
            self.origins.objects.push(place);
            let interface = self.interface(i, &mut s)?;
            let (prims, lights) = (self.prims.len(), self.lights.len());
            self.shape(i, s)?;
            self.bind_media(interface, prims, lights);
        }
        // A primitive without the attribute reads zero (as the Mitsuba
        // front-end's).
        for (index, name, scale) in std::mem::take(&mut self.attribute_textures) {
            let mut values = vec![[Color::ZERO; 3]; self.prims.len()];
            for &(prim, c) in self.mesh_attributes.get(&name).into_iter().flatten() {
                values[prim] = c;
            }
            let values = std::sync::Arc::new(values);
            self.textures[index as usize] = crate::texture::Texture::Attribute { values, scale };
        }
        for (i, l) in def.lights.into_iter().enumerate() {
            let place = self.place(l.kind.span(), format!("lights[{i}]"));
            self.light(i, l)?;
            self.origins.lights.push(place);
        }
        self.origins.camera = self.place(def.camera.span(), "camera".to_string());
        let (camera, rays_per_pixel_edge) = self.camera(&def.camera)?;
        let camera_medium = match &def.camera.get_ref().medium {
            Some(m) => Some(self.medium_ref(m, "camera.medium".to_string())?),
            None => None,
        };
        let media = self.media_parts(camera_medium);
        let ambient = match &def.ambient {
            Some(a) => self.color(&at(a, "ambient".into()))?,
            None => Color::ZERO,
        };
        if ambient != Color::ZERO {
            let span = def.ambient.as_ref().map_or(0..0, |a| a.span());
            self.not_physical.push(self.src.error(
                span,
                "ambient",
                "ambient light is the Whitted approximation of indirect light; photon mapping computes indirect \
                 light itself (remove `ambient` or set it to [0, 0, 0])",
            ));
        }
        self.check_power(ambient)?;
        let parts = SceneParts {
            prims: self.prims,
            shading_normals: self.shading_normals,
            materials: self.materials,
            lights: self.lights,
            ambient,
            camera,
            one_sided: if self.one_sided.iter().any(|&b| b) { self.one_sided } else { Vec::new() },
            paths: crate::scene::PathLimits::default(),
            texturing: Default::default(),
            media,
        };
        let mut parts = parts;
        if self.textured.iter().any(Option::is_some) || self.perturb.iter().any(Option::is_some) {
            let mut surfaces = self.surfaces;
            surfaces.resize(parts.prims.len(), crate::texture::SurfaceUv::Barycentric);
            // A triangle's coordinates are its barycentrics, as a mesh's
            // without coordinates of its own in Mitsuba (mesh.cpp).
            for (s, p) in surfaces.iter_mut().zip(&parts.prims) {
                if let (crate::texture::SurfaceUv::Barycentric, crate::shape::Shape::Triangle(_)) = (*s, &p.shape) {
                    *s = crate::texture::SurfaceUv::Triangle([glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::Y]);
                }
            }
            parts.texturing = crate::scene::Texturing {
                textures: self.textures,
                materials: self.textured,
                surfaces,
                frames: self.frames,
                perturb: self.perturb,
                light_patterns: Vec::new(),
            };
        }
        Ok(SceneFile {
            parts,
            origins: self.origins,
            rays_per_pixel_edge,
            not_physical: self.not_physical,
            meshes: self.meshes,
        })
    }

    /// The lights' power, added in double precision, must stay below
    /// [`MAX_POWER`]; the brightest light is named. Lights that all emit
    /// nothing (a radiance of 0, a disk too small for single precision to
    /// give an area) are refused at the first, as a scene without light is
    /// refused: the image would be black, whatever the summary then blames.
    fn check_power(&self, ambient: Color) -> Result<(), SceneError> {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in &self.prims {
            let (a, b) = p.shape.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        // Each light's power as the renderer sees it, placed as the scene
        // places it.
        let mut lights = self.lights.clone();
        crate::light::place_lights(&mut lights, lo, hi);
        let powers: Vec<f64> = lights.iter().map(|l| l.power().max_element() as f64).collect();
        let total: f64 = powers.iter().sum();
        // The renderer carries power in single precision: below its
        // smallest normal number a light is dark.
        if !powers.is_empty() && total < f32::MIN_POSITIVE as f64 && ambient == Color::ZERO {
            let place = self.origins.lights.first().cloned().unwrap_or_default();
            let some = if powers.len() == 1 { "" } else { ", nor does any other light" };
            return Err(self.origins.error(
                &place,
                format!(
                    "emits no light (a colour of 0, or a surface too small for single precision to give it an \
                     area){some}, so the image would be black"
                ),
            ));
        }
        if total.is_finite() && total <= MAX_POWER {
            return Ok(());
        }
        let brightest = (0..powers.len()).max_by(|&a, &b| powers[a].total_cmp(&powers[b])).unwrap_or(0);
        let place = self.origins.lights.get(brightest).cloned().unwrap_or_default();
        Err(self.origins.error(
            &place,
            format!(
                "emits {} ({} from all lights), more than single precision carries through photon and pixel \
                 sums (at most {MAX_POWER:e} W); lower its radiance and raise --exposure instead (images are \
                 linear)",
                watts(powers[brightest]),
                watts(total)
            ),
        ))
    }

    /// Where the text at `span` is, as a [`super::Place`].
    pub(super) fn place(&self, span: Range<usize>, field: String) -> super::Place {
        let e = self.src.error(span, field, "");
        super::Place { line: e.line, column: e.column, field: e.field }
    }
}

/// A power for a message: single precision's power beyond its range is
/// only "more than" it.
fn watts(p: f64) -> String {
    if p.is_finite() {
        format!("{p:.3e} W")
    } else {
        format!("more than {:.3e} W", f32::MAX)
    }
}
