//! `[materials.NAME]`: the materials a scene names, with their fields.

use super::build::{at, At, Builder};
use super::defs::V3;
use super::SceneError;
use crate::material::{Material, Phong};
use crate::math::Color;
use serde::Deserialize;
use std::ops::Range;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    pub rho: Option<Spanned<V3>>,
    pub reflectance: Option<Spanned<V3>>,
    pub ior: Option<Spanned<f32>>,
    pub absorption: Option<Spanned<V3>>,
    pub color: Option<Spanned<V3>>,
    pub m_a: Option<Spanned<f32>>,
    pub m_l: Option<Spanned<f32>>,
    pub m_s: Option<Spanned<f32>>,
    pub m_sm: Option<Spanned<f32>>,
    pub m_sp: Option<Spanned<f32>>,
    pub m_r: Option<Spanned<f32>>,
    // Mitsuba 3's parameters of its conductors, dielectrics and plastics
    // (read in mitsuba_bsdf.rs).
    pub distribution: Option<Spanned<String>>,
    pub alpha: Option<Spanned<f32>>,
    pub alpha_u: Option<Spanned<f32>>,
    pub alpha_v: Option<Spanned<f32>>,
    pub eta: Option<Spanned<V3>>,
    pub k: Option<Spanned<V3>>,
    pub int_ior: Option<Spanned<f32>>,
    pub ext_ior: Option<Spanned<f32>>,
    pub specular_reflectance: Option<Spanned<V3>>,
    pub specular_transmittance: Option<Spanned<V3>>,
    pub diffuse_reflectance: Option<Spanned<V3>>,
    pub nonlinear: Option<Spanned<bool>>,
}

/// Fields by name, with their places where given.
pub(super) type Present = Vec<(&'static str, Option<Range<usize>>)>;

impl MaterialDef {
    /// Every field's name and, where given, its place.
    pub(super) fn present(&self) -> Present {
        fn span<T>(o: &Option<Spanned<T>>) -> Option<Range<usize>> {
            o.as_ref().map(|s| s.span())
        }
        vec![
            ("rho", span(&self.rho)),
            ("reflectance", span(&self.reflectance)),
            ("ior", span(&self.ior)),
            ("absorption", span(&self.absorption)),
            ("color", span(&self.color)),
            ("m_a", span(&self.m_a)),
            ("m_l", span(&self.m_l)),
            ("m_s", span(&self.m_s)),
            ("m_sm", span(&self.m_sm)),
            ("m_sp", span(&self.m_sp)),
            ("m_r", span(&self.m_r)),
            ("distribution", span(&self.distribution)),
            ("alpha", span(&self.alpha)),
            ("alpha_u", span(&self.alpha_u)),
            ("alpha_v", span(&self.alpha_v)),
            ("eta", span(&self.eta)),
            ("k", span(&self.k)),
            ("int_ior", span(&self.int_ior)),
            ("ext_ior", span(&self.ext_ior)),
            ("specular_reflectance", span(&self.specular_reflectance)),
            ("specular_transmittance", span(&self.specular_transmittance)),
            ("diffuse_reflectance", span(&self.diffuse_reflectance)),
            ("nonlinear", span(&self.nonlinear)),
        ]
    }
}

impl Builder<'_> {
    pub(super) fn material(&self, name: &str, m: &Spanned<MaterialDef>) -> Result<Material, SceneError> {
        let d = m.get_ref();
        let f = |n: &str| format!("materials.{name}.{n}");
        let kind = at(&d.kind, f("type"));
        let others = |keep: &[&str]| -> Vec<(&str, Option<Range<usize>>)> {
            d.present().into_iter().filter(|(n, _)| !keep.contains(n)).collect()
        };
        match kind.value.as_str() {
            "lambertian" => {
                self.reject(&kind, &others(&["rho"]))?;
                let rho = self.color(&self.need(&d.rho, &kind, "rho")?)?;
                self.albedo(rho, &self.need(&d.rho, &kind, "rho")?)?;
                Ok(Material::Lambertian { rho })
            }
            "mirror" => {
                self.reject(&kind, &others(&["reflectance"]))?;
                let r = self.need(&d.reflectance, &kind, "reflectance")?;
                let reflectance = self.color(&r)?;
                self.albedo(reflectance, &r)?;
                Ok(Material::Mirror { reflectance })
            }
            "glass" => {
                self.reject(&kind, &others(&["ior", "absorption"]))?;
                let ior = self.number(&self.need(&d.ior, &kind, "ior")?, 0.0, 10.0, true)?;
                let absorption = match &d.absorption {
                    Some(a) => self.color(&at(a, f("absorption")))?,
                    None => Color::ZERO,
                };
                Ok(Material::Glass { ior, absorption })
            }
            "phong" => {
                self.reject(&kind, &others(&["color", "m_a", "m_l", "m_s", "m_sm", "m_sp", "m_r"]))?;
                let color = self.color(&self.need(&d.color, &kind, "color")?)?;
                let coef = |v: &Option<Spanned<f32>>, n: &str, hi: f32| -> Result<f32, SceneError> {
                    match v {
                        Some(s) => self.number(&at(s, f(n)), 0.0, hi, false),
                        None => Ok(0.0),
                    }
                };
                Ok(Material::Phong(Phong {
                    color,
                    ambient: coef(&d.m_a, "m_a", f32::INFINITY)?,
                    diffuse: coef(&d.m_l, "m_l", f32::INFINITY)?,
                    specular: coef(&d.m_s, "m_s", f32::INFINITY)?,
                    metalness: coef(&d.m_sm, "m_sm", 1.0)?,
                    shininess: coef(&d.m_sp, "m_sp", 1e6)?,
                    mirror: coef(&d.m_r, "m_r", f32::INFINITY)?,
                }))
            }
            "conductor" | "roughconductor" | "roughdielectric" | "thindielectric" | "plastic" | "roughplastic" => {
                self.mitsuba_bsdf(&kind, d, &others)
            }
            other => self.fail(
                kind.span.clone(),
                &kind.field,
                format!(
                    "unknown material type \"{other}\" (lambertian, mirror, glass, phong, conductor, roughconductor, \
                     roughdielectric, thindielectric, plastic, roughplastic)"
                ),
            ),
        }
    }

    /// A reflectance over one creates energy.
    pub(super) fn albedo(&self, c: Color, v: &At<V3>) -> Result<(), SceneError> {
        if c.max_element() > 1.0 {
            return self.fail(v.span.clone(), &v.field, format!("a reflectance must be at most 1, got {c}"));
        }
        Ok(())
    }

    pub(super) fn material_ref(&self, kind: &At<String>, m: &Option<Spanned<String>>) -> Result<u32, SceneError> {
        let name = self.need(m, kind, "material")?;
        self.names.get(name.value.as_str()).copied().ok_or_else(|| {
            let known: Vec<&str> = self.names.keys().map(String::as_str).collect();
            self.src.error(
                name.span.clone(),
                name.field.clone(),
                format!("no material named \"{}\" (defined: {})", name.value, known.join(", ")),
            )
        })
    }
}
