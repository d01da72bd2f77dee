//! The materials that take Mitsuba 3's BSDF parameters, with its names,
//! meanings and defaults: `conductor`, `roughconductor`,
//! `roughdielectric`, `thindielectric`, `plastic`, `roughplastic`
//! (notes/scene-format.md; the renderer's side in `material`).

use super::build::{at, At, Builder};
use super::defs::V3;
use super::material::{MaterialDef, Present};
use super::SceneError;
use crate::material::{defaults, Distribution, Material};
use crate::math::Color;
use toml::Spanned;

/// What each type reads.
fn fields(kind: &str) -> &'static [&'static str] {
    const ROUGH: [&str; 4] = ["distribution", "alpha", "alpha_u", "alpha_v"];
    match kind {
        "conductor" => &["eta", "k", "specular_reflectance"],
        "roughconductor" => &["eta", "k", "specular_reflectance", ROUGH[0], ROUGH[1], ROUGH[2], ROUGH[3]],
        "roughdielectric" => &[
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "specular_transmittance",
            ROUGH[0],
            ROUGH[1],
            ROUGH[2],
            ROUGH[3],
        ],
        "thindielectric" => &["int_ior", "ext_ior", "specular_reflectance", "specular_transmittance"],
        "plastic" => &["int_ior", "ext_ior", "specular_reflectance", "diffuse_reflectance", "nonlinear"],
        // Mitsuba's roughplastic is isotropic: alpha_u / alpha_v are
        // refused below with the reason.
        _ => &[
            "int_ior",
            "ext_ior",
            "specular_reflectance",
            "diffuse_reflectance",
            "nonlinear",
            ROUGH[0],
            ROUGH[1],
            ROUGH[2],
            ROUGH[3],
        ],
    }
}

impl Builder<'_> {
    pub(super) fn mitsuba_bsdf(
        &self,
        kind: &At<String>,
        d: &MaterialDef,
        others: &dyn Fn(&[&str]) -> Present,
    ) -> Result<Material, SceneError> {
        let name = kind.value.as_str();
        self.reject(kind, &others(fields(name)))?;
        let prefix = kind.field.trim_end_matches(".type").to_string();
        let field = |n: &str| format!("{prefix}.{n}");
        // A colour of at most 1 (a reflectance), defaulting to `default`.
        let reflectance = |v: &Option<Spanned<V3>>, n: &str, default: f32| -> Result<Color, SceneError> {
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
        let index = |v: &Option<Spanned<f32>>, n: &str, default: f32| -> Result<f32, SceneError> {
            match v {
                Some(s) => self.number(&at(s, field(n)), 0.0, 100.0, true),
                None => Ok(default),
            }
        };
        let specular = reflectance(&d.specular_reflectance, "specular_reflectance", 1.0)?;
        let int_default =
            if name.ends_with("plastic") { defaults::PLASTIC_INT_IOR } else { defaults::DIELECTRIC_INT_IOR };
        let int_ior = index(&d.int_ior, "int_ior", int_default)?;
        let ext_ior = index(&d.ext_ior, "ext_ior", defaults::EXT_IOR)?;
        if int_ior == ext_ior && name != "plastic" {
            let span = d.int_ior.as_ref().or(d.ext_ior.as_ref()).map_or(kind.span.clone(), |s| s.span());
            return self.fail(span, &field("int_ior"), format!("int_ior and ext_ior must differ, both are {int_ior}"));
        }
        Ok(match name {
            "conductor" | "roughconductor" => {
                let eta = self.optional_color(&d.eta, field("eta"), defaults::CONDUCTOR_ETA)?;
                let k = self.optional_color(&d.k, field("k"), defaults::CONDUCTOR_K)?;
                if name == "conductor" {
                    Material::conductor(eta, k, specular)
                } else {
                    let (dist, au, av) = self.roughness(kind, d, &field)?;
                    Material::rough_conductor(dist, au, av, eta, k, specular)
                }
            }
            "roughdielectric" | "thindielectric" => {
                let transmittance = reflectance(&d.specular_transmittance, "specular_transmittance", 1.0)?;
                if name == "thindielectric" {
                    Material::thin_dielectric(int_ior, ext_ior, specular, transmittance)
                } else {
                    let (dist, au, av) = self.roughness(kind, d, &field)?;
                    Material::rough_dielectric(dist, au, av, int_ior, ext_ior, specular, transmittance)
                }
            }
            _ => {
                let diffuse =
                    reflectance(&d.diffuse_reflectance, "diffuse_reflectance", defaults::DIFFUSE_REFLECTANCE)?;
                let nonlinear = d.nonlinear.as_ref().is_some_and(|b| *b.get_ref());
                if name == "plastic" {
                    Material::plastic(diffuse, specular, int_ior, ext_ior, nonlinear)
                } else {
                    if let Some(s) = d.alpha_u.as_ref().or(d.alpha_v.as_ref()) {
                        let n = if d.alpha_u.is_some() { "alpha_u" } else { "alpha_v" };
                        return self.fail(
                            s.span(),
                            &field(n),
                            "roughplastic takes one isotropic `alpha` (as Mitsuba 3's, which refuses anisotropy)",
                        );
                    }
                    let (dist, alpha, _) = self.roughness(kind, d, &field)?;
                    Material::rough_plastic(dist, alpha, diffuse, specular, int_ior, ext_ior, nonlinear)
                }
            }
        })
    }

    /// A colour that may exceed 1 (a complex index's parts), or `default`
    /// in every channel.
    fn optional_color(&self, v: &Option<Spanned<V3>>, field: String, default: f32) -> Result<Color, SceneError> {
        match v {
            Some(s) => self.color(&at(s, field)),
            None => Ok(Color::splat(default)),
        }
    }

    /// The distribution and (alpha_u, alpha_v): `alpha` alone, or both of
    /// `alpha_u` and `alpha_v`; Mitsuba's default Beckmann, alpha 0.1.
    fn roughness(
        &self,
        kind: &At<String>,
        d: &MaterialDef,
        field: &dyn Fn(&str) -> String,
    ) -> Result<(Distribution, f32, f32), SceneError> {
        let dist = match &d.distribution {
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
        match (&d.alpha, &d.alpha_u, &d.alpha_v) {
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
                format!("`alpha_u` and `alpha_v` go together (type \"{}\")", kind.value),
            ),
        }
    }
}
