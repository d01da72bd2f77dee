//! `[media.NAME]`: participating media, with Mitsuba 3's parameters and
//! defaults (as the XML front-end reads them, notes/mitsuba.md), and the
//! media a shape bounds (its `interior` and `exterior`) and the camera is
//! in (its `medium`).
//!
//! ```toml
//! [media.fog]
//! type = "homogeneous"
//! sigma_t = [0.2, 0.2, 0.2]       # or sigma_s and sigma_a
//! albedo = [0.9, 0.9, 0.9]
//! phase = { type = "hg", g = 0.5 }
//!
//! [media.smoke]
//! type = "heterogeneous"
//! sigma_t = { grid = "smoke.vol", transform = [{ scale = [2, 2, 2] }] }
//! scale = 10
//! ```

use super::build::{at, Builder};
use super::defs::{Entry, V3};
use super::shape::StepDef;
use super::SceneError;
use crate::math::Color;
use crate::medium::{Filter, Grid, Interface, MediaParts, Medium, Phase, VolGrid, Volume, Wrap};
use glam::Affine3A;
use serde::Deserialize;
use std::path::Path;
use std::sync::Arc;
use toml::Spanned;

/// `type = "homogeneous"`: one extinction everywhere.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HomogeneousDef {
    sigma_t: Option<Spanned<V3>>,
    albedo: Option<Spanned<V3>>,
    albedo_volume: Option<Spanned<VolumeDef>>,
    sigma_s: Option<Spanned<V3>>,
    sigma_a: Option<Spanned<V3>>,
    scale: Option<Spanned<f32>>,
    phase: Option<Spanned<PhaseDef>>,
    sample_emitters: Option<Spanned<bool>>,
}

/// `type = "heterogeneous"`: extinction from a volume, inside its box.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HeterogeneousDef {
    sigma_t: Spanned<VolumeDef>,
    albedo: Option<Spanned<V3>>,
    albedo_volume: Option<Spanned<VolumeDef>>,
    scale: Option<Spanned<f32>>,
    phase: Option<Spanned<PhaseDef>>,
    sample_emitters: Option<Spanned<bool>>,
}

/// A volume: a constant `value` or a `.vol` `grid`, over the unit cube
/// placed by `transform` (Mitsuba's `constvolume` and `gridvolume`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VolumeDef {
    value: Option<Spanned<V3>>,
    grid: Option<Spanned<String>>,
    transform: Option<Vec<Spanned<StepDef>>>,
    use_grid_bbox: Option<Spanned<bool>>,
    filter: Option<Spanned<String>>,
    wrap: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PhaseDef {
    #[serde(rename = "type")]
    kind: Spanned<String>,
    g: Option<Spanned<f32>>,
}

/// The scene's media as they are read.
#[derive(Default)]
pub(super) struct MediaDraft {
    names: std::collections::BTreeMap<String, u32>,
    parts: MediaParts,
}

impl Builder<'_> {
    /// `[media.NAME]`, in the order of their names.
    pub(super) fn medium(&mut self, name: String, mut entry: Entry) -> Result<(), SceneError> {
        let field = entry.field.clone();
        let f = |n: &str| format!("{field}.{n}");
        let (kind, kind_span) = (entry.kind.get_ref().clone(), entry.kind.span());
        let medium = match kind.as_str() {
            "homogeneous" => {
                let d: HomogeneousDef = entry.read(&self.src)?;
                let given = |s: &Option<Spanned<V3>>| s.as_ref().map(|v| v.span());
                let (sigma_t, albedo) = match (&d.sigma_s, &d.sigma_a) {
                    (None, None) => {
                        let sigma_t = match &d.sigma_t {
                            Some(v) => self.color(&at(v, f("sigma_t")))?,
                            None => Color::ONE,
                        };
                        (sigma_t, self.medium_albedo(&d.albedo, &d.albedo_volume, &field)?)
                    }
                    (s, a) => {
                        if let Some(span) = given(&d.sigma_t).or(given(&d.albedo)) {
                            return self.fail(
                                span,
                                &f("sigma_t"),
                                "give sigma_t and albedo, or sigma_s and sigma_a, not both",
                            );
                        }
                        if let Some(v) = &d.albedo_volume {
                            return self.fail(
                                v.span(),
                                &f("albedo_volume"),
                                "give sigma_t and albedo with an albedo volume",
                            );
                        }
                        let zero = |c: &Option<Spanned<V3>>, n| {
                            c.as_ref().map_or(Ok(Color::ZERO), |v| self.color(&at(v, f(n))))
                        };
                        let (s, a) = (zero(s, "sigma_s")?, zero(a, "sigma_a")?);
                        let t = s + a;
                        let albedo = Color::select(t.cmpgt(Color::ZERO), s / t, Color::ZERO);
                        (t, Volume::Constant { value: albedo, to_world: Affine3A::IDENTITY })
                    }
                };
                let scale = self.scale(&d.scale, &field)?;
                let phase = self.phase(&d.phase, &field)?;
                Medium::homogeneous(sigma_t, albedo, scale, phase)
                    .map(|m| with_emitters(m, &d.sample_emitters))
                    .map_err(|m| self.src.error(kind_span.clone(), field.clone(), m))?
            }
            "heterogeneous" => {
                let d: HeterogeneousDef = entry.read(&self.src)?;
                let sigma_t = self.volume(&d.sigma_t, &f("sigma_t"))?;
                let albedo = self.medium_albedo(&d.albedo, &d.albedo_volume, &field)?;
                let scale = self.scale(&d.scale, &field)?;
                let phase = self.phase(&d.phase, &field)?;
                Medium::heterogeneous(sigma_t, albedo, scale, phase)
                    .map(|m| with_emitters(m, &d.sample_emitters))
                    .map_err(|m| self.src.error(kind_span.clone(), field.clone(), m))?
            }
            other => {
                return self.fail(
                    kind_span,
                    &f("type"),
                    format!("unknown medium type \"{other}\" (homogeneous, heterogeneous)"),
                )
            }
        };
        let m = &mut self.media.parts;
        m.media.push(medium);
        self.media.names.insert(name, m.media.len() as u32 - 1);
        Ok(())
    }

    fn scale(&self, s: &Option<Spanned<f32>>, field: &str) -> Result<f32, SceneError> {
        s.as_ref().map_or(Ok(1.0), |v| self.number(&at(v, format!("{field}.scale")), 0.0, f32::INFINITY, false))
    }

    fn medium_albedo(
        &mut self,
        albedo: &Option<Spanned<V3>>,
        volume: &Option<Spanned<VolumeDef>>,
        field: &str,
    ) -> Result<Volume, SceneError> {
        match (albedo, volume) {
            (Some(_), Some(v)) => {
                self.fail(v.span(), &format!("{field}.albedo_volume"), "give albedo or albedo_volume, not both")
            }
            (Some(a), None) => Ok(Volume::Constant {
                value: self.color(&at(a, format!("{field}.albedo")))?,
                to_world: Affine3A::IDENTITY,
            }),
            (None, Some(v)) => self.volume(v, &format!("{field}.albedo_volume")),
            // Mitsuba's default.
            (None, None) => Ok(Volume::Constant { value: Color::splat(0.75), to_world: Affine3A::IDENTITY }),
        }
    }

    fn phase(&self, p: &Option<Spanned<PhaseDef>>, field: &str) -> Result<Phase, SceneError> {
        let Some(p) = p else { return Ok(Phase::Isotropic) };
        let d = p.get_ref();
        let f = format!("{field}.phase");
        match d.kind.get_ref().as_str() {
            "isotropic" => match &d.g {
                Some(g) => self.fail(g.span(), &format!("{f}.g"), "an isotropic phase function takes no g"),
                None => Ok(Phase::Isotropic),
            },
            "hg" => {
                let g = match &d.g {
                    Some(g) => *g.get_ref(),
                    None => 0.8,
                };
                if !(g > -1.0 && g < 1.0) {
                    let span = d.g.as_ref().map_or(p.span(), |g| g.span());
                    return self.fail(span, &format!("{f}.g"), format!("must lie in (-1, 1), got {g}"));
                }
                Ok(Phase::HenyeyGreenstein { g })
            }
            other => self.fail(
                d.kind.span(),
                &format!("{f}.type"),
                format!("unknown phase function \"{other}\" (isotropic, hg)"),
            ),
        }
    }

    fn volume(&mut self, v: &Spanned<VolumeDef>, field: &str) -> Result<Volume, SceneError> {
        let d = v.get_ref();
        let to_world = self.transform(&format!("{field}.transform"), &d.transform)?;
        match (&d.value, &d.grid) {
            (Some(value), None) => {
                for (name, given) in [("use_grid_bbox", d.use_grid_bbox.is_some()), ("filter", d.filter.is_some())] {
                    if given {
                        return self.fail(v.span(), &format!("{field}.{name}"), "applies to a grid, not a value");
                    }
                }
                let value = self.color(&at(value, format!("{field}.value")))?;
                Ok(Volume::Constant { value, to_world })
            }
            (None, Some(file)) => {
                let path = self.src.path.parent().unwrap_or(Path::new(".")).join(file.get_ref());
                let grid = VolGrid::read(&path).map_err(|e| self.src.error(file.span(), format!("{field}.grid"), e))?;
                self.meshes.push(path);
                let filter = match d.filter.as_ref().map(|s| (s.get_ref().as_str(), s.span())) {
                    None | Some(("trilinear", _)) => Filter::Trilinear,
                    Some(("nearest", _)) => Filter::Nearest,
                    Some((other, span)) => {
                        return self.fail(
                            span,
                            &format!("{field}.filter"),
                            format!("\"{other}\" is not trilinear or nearest"),
                        )
                    }
                };
                let wrap = match d.wrap.as_ref().map(|s| (s.get_ref().as_str(), s.span())) {
                    None | Some(("clamp", _)) => Wrap::Clamp,
                    Some(("repeat", _)) => Wrap::Repeat,
                    Some(("mirror", _)) => Wrap::Mirror,
                    Some((other, span)) => {
                        return self.fail(
                            span,
                            &format!("{field}.wrap"),
                            format!("\"{other}\" is not clamp, repeat or mirror"),
                        )
                    }
                };
                let use_bbox = d.use_grid_bbox.as_ref().is_some_and(|b| *b.get_ref());
                Grid::new(Arc::new(grid), to_world, use_bbox, filter, wrap).map(Volume::Grid).ok_or_else(|| {
                    self.src.error(
                        file.span(),
                        format!("{field}.grid"),
                        "the grid's box is empty or its placement singular",
                    )
                })
            }
            _ => self.fail(v.span(), field, "a volume is a constant `value` or a `grid` file, one of the two"),
        }
    }

    /// A shape's `interior` and `exterior`, taken from its table before
    /// its type reads the rest.
    pub(super) fn interface(&self, i: usize, entry: &mut Entry) -> Result<Option<Interface>, SceneError> {
        let mut interface = Interface::default();
        for (key, slot) in [("interior", &mut interface.interior), ("exterior", &mut interface.exterior)] {
            if let Some(value) = entry.take(key) {
                let name: Spanned<String> = self.src.read(value, &format!("shapes[{i}].{key}"))?;
                *slot = Some(self.medium_ref(&name, format!("shapes[{i}].{key}"))?);
            }
        }
        Ok((interface != Interface::default()).then_some(interface))
    }

    /// Binds `interface` to the primitives and lights added since the
    /// counts `prims` and `lights`.
    pub(super) fn bind_media(&mut self, interface: Option<Interface>, prims: usize, lights: usize) {
        let Some(i) = interface else { return };
        let d = &mut self.media.parts;
        d.prims.resize(prims, None);
        d.prims.resize(self.prims.len(), Some(i));
        d.lights.resize(lights, None);
        d.lights.resize(self.lights.len(), Some(i));
    }

    /// The medium `name` names.
    pub(super) fn medium_ref(&self, name: &Spanned<String>, field: String) -> Result<u32, SceneError> {
        self.media.names.get(name.get_ref().as_str()).copied().ok_or_else(|| {
            let known: Vec<&str> = self.media.names.keys().map(String::as_str).collect();
            let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
            self.src.error(name.span(), field, format!("no medium named \"{}\" (defined: {known})", name.get_ref()))
        })
    }

    /// What the scene's parts hold of its media, the camera's `medium` set.
    pub(super) fn media_parts(&mut self, camera: Option<u32>) -> MediaParts {
        let mut parts = std::mem::take(&mut self.media.parts);
        parts.camera = camera;
        parts
    }
}

fn with_emitters(mut m: Medium, sample_emitters: &Option<Spanned<bool>>) -> Medium {
    m.sample_emitters = sample_emitters.as_ref().is_none_or(|b| *b.get_ref());
    m
}
