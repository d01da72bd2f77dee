//! `[materials.NAME]`: the materials a scene names, with their fields.

use super::bsdf::{Built, NOTHING};
use super::build::{at, At, Builder};
use super::defs::{Entry, V3};
use super::SceneError;
use crate::material::{Material, Phong};
use crate::math::Color;
use serde::Deserialize;
use toml::Spanned;

/// `type = "lambertian"`: ideal diffuse.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LambertianDef {
    rho: Spanned<V3>,
}

/// `type = "mirror"`: a perfect mirror.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MirrorDef {
    reflectance: Spanned<V3>,
}

/// `type = "glass"`: a smooth dielectric, optionally absorbing.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GlassDef {
    ior: Spanned<f32>,
    absorption: Option<Spanned<V3>>,
}

/// `type = "null"`: nothing there, light passes straight through: the
/// index-matched boundary of a participating medium (Mitsuba's `null`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NullDef {}

/// `type = "phong"`: the CS475 material.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PhongDef {
    color: Spanned<V3>,
    m_a: Option<Spanned<f32>>,
    m_l: Option<Spanned<f32>>,
    m_s: Option<Spanned<f32>>,
    m_sm: Option<Spanned<f32>>,
    m_sp: Option<Spanned<f32>>,
    m_r: Option<Spanned<f32>>,
}

impl<'a> Builder<'a> {
    /// A material table (named or inline).
    pub(super) fn material(&mut self, entry: &mut Entry<'a>) -> Result<Built, SceneError> {
        let plain = match self.plain_material(entry)? {
            Some(m) => m,
            None => match self.bsdf(entry)? {
                Some(built) => return Ok(built),
                None => {
                    let kind = entry.kind();
                    return self.fail(
                        kind.span.clone(),
                        &kind.field,
                        format!(
                            "unknown material type \"{}\" (lambertian, mirror, glass, phong, null, diffuse, conductor, \
                             roughconductor, roughdielectric, thindielectric, plastic, roughplastic, principled, \
                             principledthin, blendbsdf, mask, bumpmap, normalmap, twosided)",
                            kind.value
                        ),
                    );
                }
            },
        };
        Ok((plain, None, false, None))
    }

    /// The materials of photonmap's own types, or `None` for another type.
    fn plain_material(&self, entry: &mut Entry) -> Result<Option<Material>, SceneError> {
        let prefix = entry.field.clone();
        let f = |n: &str| format!("{prefix}.{n}");
        let m = match entry.kind.get_ref().as_str() {
            "lambertian" => {
                let d: LambertianDef = entry.read(&self.src)?;
                let rho = at(&d.rho, f("rho"));
                let c = self.color(&rho)?;
                self.albedo(c, &rho)?;
                Ok(Material::Lambertian { rho: c })
            }
            "mirror" => {
                let d: MirrorDef = entry.read(&self.src)?;
                let r = at(&d.reflectance, f("reflectance"));
                let reflectance = self.color(&r)?;
                self.albedo(reflectance, &r)?;
                Ok(Material::Mirror { reflectance })
            }
            "glass" => {
                let d: GlassDef = entry.read(&self.src)?;
                let ior = self.number(&at(&d.ior, f("ior")), 0.0, 10.0, true)?;
                let absorption = match &d.absorption {
                    Some(a) => self.color(&at(a, f("absorption")))?,
                    None => Color::ZERO,
                };
                Ok(Material::Glass { ior, absorption })
            }
            "phong" => {
                let d: PhongDef = entry.read(&self.src)?;
                let color = self.color(&at(&d.color, f("color")))?;
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
            "null" => {
                let _: NullDef = entry.read(&self.src)?;
                Ok(NOTHING)
            }
            _ => return Ok(None),
        };
        m.map(Some)
    }

    /// A reflectance over one creates energy.
    pub(super) fn albedo(&self, c: Color, v: &At<V3>) -> Result<(), SceneError> {
        if c.max_element() > 1.0 {
            return self.fail(v.span.clone(), &v.field, format!("a reflectance must be at most 1, got {c}"));
        }
        Ok(())
    }

    /// The index of the material named at `name` (the field `field`),
    /// built now if it is not yet (a material nested by name).
    pub(super) fn material_ref(&mut self, name: &Spanned<String>, field: String) -> Result<u32, SceneError> {
        if let Some(&m) = self.names.get(name.get_ref().as_str()) {
            return Ok(m);
        }
        if self.defining.iter().any(|d| d == name.get_ref()) {
            return self.fail(
                name.span(),
                &field,
                format!("material \"{}\" contains itself (through {})", name.get_ref(), self.defining.join(" -> ")),
            );
        }
        if self.pending.contains_key(name.get_ref()) {
            return self.define_material(name.get_ref());
        }
        Err({
            let mut known: Vec<&str> = self.names.keys().map(String::as_str).collect();
            known.extend(self.pending.keys().map(String::as_str));
            known.sort();
            self.src.error(
                name.span(),
                field,
                format!("no material named \"{}\" (defined: {})", name.get_ref(), known.join(", ")),
            )
        })
    }

    /// Builds the pending material `name` and gives its index.
    pub(super) fn define_material(&mut self, name: &str) -> Result<u32, SceneError> {
        if let Some(&m) = self.names.get(name) {
            return Ok(m);
        }
        let Some(mut entry) = self.pending.remove(name) else {
            return self.fail(0..0, name, "no such material");
        };
        self.defining.push(name.to_string());
        let built = self.material(&mut entry)?;
        self.defining.pop();
        if let Material::Phong(p) = built.0 {
            if p.albedo_bound() > 1.0 {
                self.not_physical.push(self.src.error(
                    entry.kind.span(),
                    format!("materials.{name}"),
                    format!(
                        "m_l C + m_s S + m_r C reaches {:.3} > 1: the material reflects more light than it \
                         receives, which photon mapping cannot render (lower m_l, m_s or m_r)",
                        p.albedo_bound()
                    ),
                ));
            }
        }
        let place = self.place(entry.kind.span(), format!("materials.{name}"));
        let m = self.push_material(built, place);
        self.names.insert(name.to_string(), m);
        Ok(m)
    }

    /// Adds a material, written at `place`.
    pub(super) fn push_material(&mut self, built: Built, place: super::Place) -> u32 {
        let (material, textured, one_sided, perturb) = built;
        self.materials.push(material);
        self.textured.push(textured);
        self.one_sided.push(one_sided);
        self.perturb.push(perturb);
        self.origins.materials.push(place);
        self.materials.len() as u32 - 1
    }
}
