//! The materials that take Mitsuba 3's BSDF parameters, with its names,
//! meanings and defaults: `conductor`, `roughconductor`,
//! `roughdielectric`, `thindielectric`, `plastic`, `roughplastic`
//! (notes/scene-format.md; the renderer's side in `material`).

use super::build::{at, Builder};
use super::defs::{Entry, V3};
use super::SceneError;
use crate::material::{defaults, Distribution, Material};
use crate::math::Color;
use serde::Deserialize;
use toml::Spanned;

type Value<T> = Option<Spanned<T>>;

/// `type = "conductor"`: a smooth metal.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConductorDef {
    eta: Value<V3>,
    k: Value<V3>,
    specular_reflectance: Value<V3>,
}

/// `type = "roughconductor"`: a rough metal.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RoughConductorDef {
    eta: Value<V3>,
    k: Value<V3>,
    specular_reflectance: Value<V3>,
    distribution: Value<String>,
    alpha: Value<f32>,
    alpha_u: Value<f32>,
    alpha_v: Value<f32>,
}

/// `type = "roughdielectric"`: rough glass.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RoughDielectricDef {
    int_ior: Value<f32>,
    ext_ior: Value<f32>,
    specular_reflectance: Value<V3>,
    specular_transmittance: Value<V3>,
    distribution: Value<String>,
    alpha: Value<f32>,
    alpha_u: Value<f32>,
    alpha_v: Value<f32>,
}

/// `type = "thindielectric"`: a thin pane.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ThinDielectricDef {
    int_ior: Value<f32>,
    ext_ior: Value<f32>,
    specular_reflectance: Value<V3>,
    specular_transmittance: Value<V3>,
}

/// `type = "plastic"`: a diffuse base under a smooth coat.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlasticDef {
    int_ior: Value<f32>,
    ext_ior: Value<f32>,
    specular_reflectance: Value<V3>,
    diffuse_reflectance: Value<V3>,
    nonlinear: Value<bool>,
}

/// `type = "roughplastic"`: a diffuse base under a rough coat, isotropic
/// as Mitsuba's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RoughPlasticDef {
    int_ior: Value<f32>,
    ext_ior: Value<f32>,
    specular_reflectance: Value<V3>,
    diffuse_reflectance: Value<V3>,
    nonlinear: Value<bool>,
    distribution: Value<String>,
    alpha: Value<f32>,
}

/// A microfacet type's roughness fields.
struct Rough<'a> {
    distribution: &'a Value<String>,
    alpha: &'a Value<f32>,
    alpha_u: &'a Value<f32>,
    alpha_v: &'a Value<f32>,
}

impl Builder<'_> {
    /// The material of a Mitsuba type's table (`entry`), or None where the
    /// type is not one of them.
    pub(super) fn mitsuba_bsdf(&self, entry: &mut Entry) -> Result<Option<Material>, SceneError> {
        let name = entry.kind.get_ref().clone();
        let prefix = entry.field.clone();
        let kind_span = entry.kind.span();
        let field = |n: &str| format!("{prefix}.{n}");
        // A colour of at most 1 (a reflectance), defaulting to `default`.
        let reflectance = |v: &Value<V3>, n: &str, default: f32| -> Result<Color, SceneError> {
            match v {
                Some(s) => {
                    let a = at(s, field(n));
                    let c = self.color(&a)?;
                    self.albedo(c, &a)?;
                    Ok(c)
                }
                None => Ok(Color::splat(default)),
            }
        };
        // The interior and exterior indices, which must differ where an
        // interface between them is rendered.
        let indices = |int: &Value<f32>, ext: &Value<f32>, int_default: f32| -> Result<(f32, f32), SceneError> {
            let index = |v: &Value<f32>, n: &str, default: f32| match v {
                Some(s) => self.number(&at(s, field(n)), 0.0, 100.0, true),
                None => Ok(default),
            };
            let (i, e) = (index(int, "int_ior", int_default)?, index(ext, "ext_ior", defaults::EXT_IOR)?);
            if i == e && name != "plastic" {
                let span = int.as_ref().or(ext.as_ref()).map_or(kind_span.clone(), |s| s.span());
                return self.fail(span, &field("int_ior"), format!("int_ior and ext_ior must differ, both are {i}"));
            }
            Ok((i, e))
        };
        let metal = |eta: &Value<V3>, k: &Value<V3>| -> Result<(Color, Color), SceneError> {
            let eta = self.optional_color(eta, field("eta"), defaults::CONDUCTOR_ETA)?;
            Ok((eta, self.optional_color(k, field("k"), defaults::CONDUCTOR_K)?))
        };
        Ok(Some(match name.as_str() {
            "conductor" => {
                let d: ConductorDef = entry.read(&self.src)?;
                let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
                let (eta, k) = metal(&d.eta, &d.k)?;
                Material::conductor(eta, k, specular)
            }
            "roughconductor" => {
                let d: RoughConductorDef = entry.read(&self.src)?;
                let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
                let (eta, k) = metal(&d.eta, &d.k)?;
                let rough =
                    Rough { distribution: &d.distribution, alpha: &d.alpha, alpha_u: &d.alpha_u, alpha_v: &d.alpha_v };
                let (dist, au, av) = self.roughness(&name, rough, &field)?;
                Material::rough_conductor(dist, au, av, eta, k, specular)
            }
            "roughdielectric" => {
                let d: RoughDielectricDef = entry.read(&self.src)?;
                let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
                let (int_ior, ext_ior) = indices(&d.int_ior, &d.ext_ior, defaults::DIELECTRIC_INT_IOR)?;
                let transmittance = reflectance(&d.specular_transmittance, "specular_transmittance", 1.0)?;
                let rough =
                    Rough { distribution: &d.distribution, alpha: &d.alpha, alpha_u: &d.alpha_u, alpha_v: &d.alpha_v };
                let (dist, au, av) = self.roughness(&name, rough, &field)?;
                Material::rough_dielectric(dist, au, av, int_ior, ext_ior, specular, transmittance)
            }
            "thindielectric" => {
                let d: ThinDielectricDef = entry.read(&self.src)?;
                let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
                let (int_ior, ext_ior) = indices(&d.int_ior, &d.ext_ior, defaults::DIELECTRIC_INT_IOR)?;
                let transmittance = reflectance(&d.specular_transmittance, "specular_transmittance", 1.0)?;
                Material::thin_dielectric(int_ior, ext_ior, specular, transmittance)
            }
            "plastic" => {
                let d: PlasticDef = entry.read(&self.src)?;
                let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
                let (int_ior, ext_ior) = indices(&d.int_ior, &d.ext_ior, defaults::PLASTIC_INT_IOR)?;
                let diffuse =
                    reflectance(&d.diffuse_reflectance, "diffuse_reflectance", defaults::DIFFUSE_REFLECTANCE)?;
                let nonlinear = d.nonlinear.as_ref().is_some_and(|b| *b.get_ref());
                Material::plastic(diffuse, specular, int_ior, ext_ior, nonlinear)
            }
            "roughplastic" => {
                let d: RoughPlasticDef = entry.read(&self.src).map_err(|mut e| {
                    if e.field.ends_with(".alpha_u") || e.field.ends_with(".alpha_v") {
                        e.message = "roughplastic takes one isotropic `alpha` (as Mitsuba 3's, which refuses \
                                     anisotropy)"
                            .into();
                    }
                    e
                })?;
                let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
                let (int_ior, ext_ior) = indices(&d.int_ior, &d.ext_ior, defaults::PLASTIC_INT_IOR)?;
                let diffuse =
                    reflectance(&d.diffuse_reflectance, "diffuse_reflectance", defaults::DIFFUSE_REFLECTANCE)?;
                let nonlinear = d.nonlinear.as_ref().is_some_and(|b| *b.get_ref());
                let rough = Rough { distribution: &d.distribution, alpha: &d.alpha, alpha_u: &None, alpha_v: &None };
                let (dist, alpha, _) = self.roughness(&name, rough, &field)?;
                Material::rough_plastic(dist, alpha, diffuse, specular, int_ior, ext_ior, nonlinear)
            }
            _ => return Ok(None),
        }))
    }

    /// A colour that may exceed 1 (a complex index's parts), or `default`
    /// in every channel.
    fn optional_color(&self, v: &Value<V3>, field: String, default: f32) -> Result<Color, SceneError> {
        match v {
            Some(s) => self.color(&at(s, field)),
            None => Ok(Color::splat(default)),
        }
    }

    /// The distribution and (alpha_u, alpha_v): `alpha` alone, or both of
    /// `alpha_u` and `alpha_v`; Mitsuba's default Beckmann, alpha 0.1.
    fn roughness(
        &self,
        kind: &str,
        d: Rough,
        field: &dyn Fn(&str) -> String,
    ) -> Result<(Distribution, f32, f32), SceneError> {
        let dist = match d.distribution {
            None => defaults::DISTRIBUTION,
            Some(s) => match Distribution::from_name(s.get_ref()) {
                Some(dist) => dist,
                None => {
                    return self.fail(
                        s.span(),
                        &field("distribution"),
                        format!("unknown distribution \"{}\" (beckmann, ggx)", s.get_ref()),
                    )
                }
            },
        };
        let alpha = |s: &Spanned<f32>, n: &str| self.number(&at(s, field(n)), 0.0, 10.0, false);
        match (d.alpha, d.alpha_u, d.alpha_v) {
            (Some(a), None, None) => {
                let a = alpha(a, "alpha")?;
                Ok((dist, a, a))
            }
            (None, Some(u), Some(v)) => Ok((dist, alpha(u, "alpha_u")?, alpha(v, "alpha_v")?)),
            (None, None, None) => Ok((dist, defaults::ALPHA, defaults::ALPHA)),
            (Some(a), _, _) => self.fail(a.span(), &field("alpha"), "give either `alpha` or `alpha_u` and `alpha_v`"),
            (None, Some(s), None) | (None, None, Some(s)) => self.fail(
                s.span(),
                &field(if d.alpha_u.is_some() { "alpha_u" } else { "alpha_v" }),
                format!("`alpha_u` and `alpha_v` go together (type \"{kind}\")"),
            ),
        }
    }
}
