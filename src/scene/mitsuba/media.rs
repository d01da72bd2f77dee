//! `<medium>`, `<phase>` and `<volume>` plugins (Mitsuba 3's src/media/,
//! src/phase/, src/volumes/; parameters and defaults from its plugin
//! documentation), and the media a shape's `interior` / `exterior` and a
//! sensor's `medium` name.
//!
//! * `homogeneous`: `sigma_t` (default 1) and `albedo` (default 0.75) or,
//!   as Mitsuba 0.6 wrote them, `sigma_s` and `sigma_a`; `scale`
//!   (default 1), `sample_emitters` (default true), one nested phase
//!   (default `isotropic`). `sigma_t` is a colour or a `constvolume`;
//!   `albedo` any volume.
//! * `heterogeneous`: the same, `sigma_t` any volume (a colour stands for
//!   a `constvolume` of the unit cube, as in Mitsuba, whose box bounds the
//!   density).
//! * `gridvolume` (`filename` of a `.vol` file, `to_world`,
//!   `use_grid_bbox`, `filter_type`, `wrap_mode`; `raw` and `accel` change
//!   nothing in RGB), `constvolume` (`value`, `to_world`).
//! * `isotropic`, `hg` (`g`, default 0.8).
//!
//! Colours are read as Mitsuba's RGB variants read them: a `<spectrum>`
//! of wavelength:value pairs is converted as an unbounded quantity
//! (`spectrum.rs`).

use super::props::{Plugin, Value};
use super::spectrum::Use;
use super::Builder;
use crate::math::Color;
use crate::medium::{Filter, Grid, Interface, MediaParts, Medium, Phase, VolGrid, Volume, Wrap};
use crate::scene::file::SceneError;
use glam::{Affine3A, DAffine3};
use std::sync::Arc;

/// What a builder keeps of the scene's media.
#[derive(Default)]
pub(super) struct MediaDraft {
    media: Vec<Medium>,
    /// Media already built, by element address: a medium shared by
    /// reference is one medium.
    cache: Vec<(*const super::xml::Element, u32)>,
    grids: Vec<(std::path::PathBuf, Arc<VolGrid>)>,
    prims: Vec<Option<Interface>>,
    lights: Vec<Option<Interface>>,
    camera: Option<u32>,
}

impl Builder<'_> {
    /// A shape's `interior` and `exterior` media; `None` where it names
    /// neither (it changes no ray's medium).
    pub(super) fn interface(&mut self, p: &Plugin) -> Result<Option<Interface>, SceneError> {
        let mut interface = Interface::default();
        let mut any = false;
        for (name, m) in p.named_objects("medium")? {
            let slot = match name {
                Some("interior") => &mut interface.interior,
                Some("exterior") => &mut interface.exterior,
                _ => {
                    return Err(p.fail(
                        m.loc(),
                        name.unwrap_or("medium"),
                        "a shape's medium is named 'interior' or 'exterior'",
                    ))
                }
            };
            if slot.is_some() {
                return Err(p.fail(m.loc(), name.unwrap_or("medium"), "given twice"));
            }
            *slot = Some(self.medium(&m)?);
            any = true;
        }
        Ok(any.then_some(interface))
    }

    /// Binds `interface` to the primitives and lights pushed since the
    /// counts `prims` and `lights`.
    pub(super) fn bind_media(&mut self, interface: Option<Interface>, prims: usize, lights: usize) {
        let Some(i) = interface else { return };
        let d = &mut self.media;
        d.prims.resize(prims, None);
        d.prims.resize(self.prims.len(), Some(i));
        d.lights.resize(lights, None);
        d.lights.resize(self.lights.len(), Some(i));
    }

    /// A sensor's `medium`, marked read so the sensor's own reader does
    /// not refuse it.
    pub(super) fn sensor_medium(&mut self, p: &Plugin) -> Result<(), SceneError> {
        for (name, m) in p.named_objects("medium")? {
            if name != Some("medium") {
                return Err(p.fail(m.loc(), name.unwrap_or("medium"), "a sensor's medium is named 'medium'"));
            }
            if self.media.camera.is_some() {
                return Err(p.fail(m.loc(), "medium", "given twice"));
            }
            self.media.camera = Some(self.medium(&m)?);
        }
        Ok(())
    }

    /// What the scene's parts hold of its media.
    pub(super) fn media_parts(&mut self) -> MediaParts {
        let d = std::mem::take(&mut self.media);
        MediaParts { media: d.media, prims: d.prims, lights: d.lights, camera: d.camera }
    }

    /// The index of the medium `p` is, built the first time it is met.
    fn medium(&mut self, p: &Plugin) -> Result<u32, SceneError> {
        let key = p.el as *const super::xml::Element;
        if let Some(&(_, i)) = self.media.cache.iter().find(|(k, _)| *k == key) {
            return Ok(i);
        }
        let homogeneous = match p.kind {
            "homogeneous" => true,
            "heterogeneous" => false,
            k => return Err(p.refuse(format!("the '{k}' medium is not supported (homogeneous and heterogeneous are)"))),
        };
        let scale = p.float_in("scale", 1.0, 0.0, 1e30)? as f32;
        let sample_emitters = p.boolean("sample_emitters", true)?;
        let spectral = p.boolean("has_spectral_extinction", true)?;
        let phase = match p.object("phase")? {
            None => Phase::Isotropic,
            Some(q) => phase(&q)?,
        };
        let (sigma_s, sigma_a) = (p.tag_of("sigma_s").is_some(), p.tag_of("sigma_a").is_some());
        let (sigma_t, albedo) = if homogeneous && (sigma_s || sigma_a) {
            // Mitsuba 0.6's parameters: σ_t = σ_s + σ_a, albedo σ_s / σ_t.
            for other in ["sigma_t", "albedo"] {
                if p.tag_of(other).is_some() {
                    return Err(p.fail(
                        &p.named_loc(other),
                        other,
                        "give sigma_t and albedo, or sigma_s and sigma_a, not both",
                    ));
                }
            }
            let s = p.color("sigma_s", Use::Unbounded)?.unwrap_or(Color::ZERO);
            let a = p.color("sigma_a", Use::Unbounded)?.unwrap_or(Color::ZERO);
            if s.min_element() < 0.0 || a.min_element() < 0.0 {
                return Err(p.refuse("sigma_s and sigma_a must not be negative"));
            }
            let t = s + a;
            let albedo = Color::select(t.cmpgt(Color::ZERO), s / t, Color::ZERO);
            (Volume::Constant { value: t, to_world: Affine3A::IDENTITY }, constant(albedo))
        } else {
            let sigma_t = self.volume(p, "sigma_t", 1.0)?;
            let albedo = self.volume(p, "albedo", 0.75)?;
            (sigma_t, albedo)
        };
        p.finish(
            "sigma_t, albedo, sigma_s and sigma_a (homogeneous), scale, sample_emitters, has_spectral_extinction, \
             one nested <phase>",
        )?;
        if !spectral && sigma_t.constant().is_none_or(|c| c.max_element() != c.min_element()) {
            return Err(p.fail(
                &p.named_loc("has_spectral_extinction"),
                "has_spectral_extinction",
                "false is supported where sigma_t is the same in every channel (photonmap renders each channel's \
                 own extinction)",
            ));
        }
        let built = if homogeneous {
            let Some(value) = sigma_t.constant() else {
                return Err(p.fail(
                    &p.named_loc("sigma_t"),
                    "sigma_t",
                    "a homogeneous medium's sigma_t is a colour or a constvolume (a grid is a heterogeneous medium)",
                ));
            };
            Medium::homogeneous(value, albedo, scale, phase)
        } else {
            Medium::heterogeneous(sigma_t, albedo, scale, phase)
        };
        let mut medium = built.map_err(|m| p.refuse(m))?;
        medium.sample_emitters = sample_emitters;
        let i = self.media.media.len() as u32;
        self.media.media.push(medium);
        self.media.cache.push((key, i));
        Ok(i)
    }

    /// A medium's parameter `name` as a volume: a colour (a constant over
    /// the unit cube, Mitsuba's shorthand) or a nested `<volume>`.
    fn volume(&mut self, p: &Plugin, name: &str, default: f32) -> Result<Volume, SceneError> {
        if let Some(v) = p.object_named(name, "volume")? {
            return self.volume_plugin(&v);
        }
        match p.value(name, Use::Unbounded)? {
            None => Ok(constant(Color::splat(default))),
            Some(Value::Color(c)) => Ok(constant(c)),
            Some(Value::Texture(t)) => Err(p.fail(
                t.loc(),
                name,
                format!("a texture ('{}') is not a volume; give a colour or a <volume>", t.kind),
            )),
        }
    }

    fn volume_plugin(&mut self, v: &Plugin) -> Result<Volume, SceneError> {
        let to_world = affine(&v.transform("to_world")?.unwrap_or(DAffine3::IDENTITY));
        if !(to_world.matrix3.determinant().abs() > 0.0) {
            return Err(v.fail(&v.named_loc("to_world"), "to_world", "the transform is singular"));
        }
        match v.kind {
            "constvolume" => {
                let value = match v.value("value", Use::Unbounded)? {
                    None => Color::ONE,
                    Some(Value::Color(c)) => c,
                    Some(Value::Texture(t)) => {
                        return Err(v.fail(t.loc(), "value", "a constvolume's value is a colour"))
                    }
                };
                v.finish("value, to_world")?;
                Ok(Volume::Constant { value, to_world })
            }
            "gridvolume" => {
                let (file, loc) = v.string("filename")?.ok_or_else(|| v.refuse("needs a filename"))?;
                let use_grid_bbox = v.boolean("use_grid_bbox", false)?;
                let filter = match v.string("filter_type")? {
                    None => Filter::Trilinear,
                    Some((f, at)) => match f.as_str() {
                        "trilinear" => Filter::Trilinear,
                        "nearest" => Filter::Nearest,
                        _ => return Err(v.fail(&at, "filter_type", format!("'{f}' is not trilinear or nearest"))),
                    },
                };
                let wrap = match v.string("wrap_mode")? {
                    None => Wrap::Clamp,
                    Some((w, at)) => match w.as_str() {
                        "clamp" => Wrap::Clamp,
                        "repeat" => Wrap::Repeat,
                        "mirror" => Wrap::Mirror,
                        _ => return Err(v.fail(&at, "wrap_mode", format!("'{w}' is not clamp, repeat or mirror"))),
                    },
                };
                // RGB variants convert nothing (`raw`), and `accel` is the
                // GPU's texture hardware: neither changes the image here.
                v.boolean("raw", false)?;
                v.boolean("accel", true)?;
                v.finish("filename, to_world, use_grid_bbox, filter_type, wrap_mode, raw, accel")?;
                let path = self.resolve(&file, &loc)?;
                let data = match self.media.grids.iter().find(|(p, _)| *p == path) {
                    Some((_, g)) => g.clone(),
                    None => {
                        let g = Arc::new(VolGrid::read(&path).map_err(|e| v.fail(&loc, "filename", e))?);
                        self.media.grids.push((path, g.clone()));
                        g
                    }
                };
                let grid = Grid::new(data, to_world, use_grid_bbox, filter, wrap).ok_or_else(|| {
                    v.fail(&loc, "use_grid_bbox", "the file's bounding box is empty, so the grid cannot be placed")
                })?;
                Ok(Volume::Grid(grid))
            }
            k => Err(v.refuse(format!("the '{k}' volume is not supported (gridvolume and constvolume are)"))),
        }
    }
}

fn phase(q: &Plugin) -> Result<Phase, SceneError> {
    match q.kind {
        "isotropic" => {
            q.finish("nothing")?;
            Ok(Phase::Isotropic)
        }
        "hg" => {
            let g = q.float_or("g", 0.8)?;
            if !(g > -1.0 && g < 1.0) {
                return Err(q.fail(&q.named_loc("g"), "g", format!("must lie in (-1, 1), got {g}")));
            }
            q.finish("g")?;
            Ok(Phase::HenyeyGreenstein { g: g as f32 })
        }
        k => Err(q.refuse(format!("the '{k}' phase function is not supported (isotropic and hg are)"))),
    }
}

fn constant(c: Color) -> Volume {
    Volume::Constant { value: c, to_world: Affine3A::IDENTITY }
}

fn affine(m: &DAffine3) -> Affine3A {
    Affine3A::from_mat3_translation(m.matrix3.as_mat3(), m.translation.as_vec3())
}
