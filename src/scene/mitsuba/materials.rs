//! `<bsdf>` plugins as photonmap's materials. Mitsuba's BSDFs reflect on
//! the front of a surface only (black behind the geometric normal) unless
//! wrapped in `twosided`; its dielectrics are two-sided by nature
//! (src/bsdfs/*.cpp). A shape with no BSDF is Mitsuba's default, a
//! diffuse reflectance of 0.5.

use super::props::Plugin;
use super::spectrum::{named_ior, Use};
use super::Builder;
use crate::material::Material;
use crate::math::Color;
use crate::scene::file::SceneError;

/// A material and whether it is one-sided.
type Built = (Material, bool);

impl Builder<'_> {
    /// The material index of a shape's BSDF (`None`: Mitsuba's default).
    pub(super) fn material(&mut self, bsdf: Option<&Plugin>) -> Result<u32, SceneError> {
        let key = bsdf.map_or(std::ptr::null(), |p| p.el as *const _);
        if let Some(&(_, m)) = self.material_cache.iter().find(|(k, _)| *k == key) {
            return Ok(m);
        }
        let (material, one_sided) = match bsdf {
            None => (Material::Lambertian { rho: Color::splat(0.5) }, true),
            Some(p) => match bsdf_of(p) {
                Ok(built) => built,
                Err(e) => {
                    self.substitute(p, "a grey diffuse BSDF (reflectance 0.5) stands in", e)?;
                    (Material::Lambertian { rho: Color::splat(0.5) }, true)
                }
            },
        };
        let m = self.materials.len() as u32;
        self.materials.push(material);
        self.one_sided.push(one_sided);
        self.material_cache.push((key, m));
        Ok(m)
    }
}

fn bsdf_of(p: &Plugin) -> Result<Built, SceneError> {
    match p.kind {
        "diffuse" => {
            let rho = p.color("reflectance", Use::Reflectance)?.unwrap_or(Color::splat(0.5));
            p.finish("reflectance")?;
            Ok((Material::Lambertian { rho: bounded(p, "reflectance", rho)? }, true))
        }
        "dielectric" => {
            let int = ior(p, "int_ior", "bk7")?;
            let ext = ior(p, "ext_ior", "air")?;
            for name in ["specular_reflectance", "specular_transmittance"] {
                if let Some(c) = p.color(name, Use::Reflectance)? {
                    if c != Color::ONE {
                        return Err(p.fail(p.loc(), name, "only 1 (clear glass) is supported"));
                    }
                }
            }
            p.finish("int_ior, ext_ior")?;
            Ok((Material::glass((int / ext) as f32), false))
        }
        "conductor" => {
            let name = p.string("material")?;
            let tint = p.color("specular_reflectance", Use::Reflectance)?.unwrap_or(Color::ONE);
            match name {
                Some((m, _)) if m == "none" => {}
                Some((m, loc)) => {
                    return Err(p.fail(
                        &loc,
                        "material",
                        format!("the named conductor '{m}' is not supported yet (only 'none', a perfect mirror)"),
                    ))
                }
                None if p.el.children.iter().any(|c| matches!(c.attr("name"), Some("eta" | "k"))) => {
                    return Err(p.refuse("a conductor's eta and k (complex Fresnel) are not supported yet; 'none' is"))
                }
                // Mitsuba's default is 'none', a perfect mirror.
                None => {}
            }
            p.finish("material ('none'), specular_reflectance")?;
            Ok((Material::Mirror { reflectance: bounded(p, "specular_reflectance", tint)? }, true))
        }
        "twosided" => {
            let inner = p.objects("bsdf")?;
            p.finish("one or two nested <bsdf>")?;
            match &inner[..] {
                [one] => {
                    let (m, _) = bsdf_of(one)?;
                    Ok((m, false))
                }
                [_, two] => Err(two.refuse("a twosided BSDF with a different back BSDF is not supported yet")),
                _ => Err(p.refuse("a twosided BSDF needs one nested <bsdf>")),
            }
        }
        k => Err(p.refuse(format!(
            "the '{k}' BSDF is not supported yet (diffuse, dielectric, conductor 'none' and twosided are)"
        ))),
    }
}

/// A reflectance within [0, 1] per channel.
fn bounded(p: &Plugin, name: &str, c: Color) -> Result<Color, SceneError> {
    if c.min_element() < 0.0 || c.max_element() > 1.0 {
        return Err(p.fail(p.loc(), name, format!("a reflectance must lie in [0, 1], got {c}")));
    }
    Ok(c)
}

/// An index of refraction: a number or a name from Mitsuba's table.
fn ior(p: &Plugin, name: &str, default: &str) -> Result<f64, SceneError> {
    if p.tag_of(name) == Some("string") {
        let (text, loc) = p.string(name)?.expect("a string, looked at");
        return named_ior(&text).map(|v| v as f64).ok_or_else(|| {
            p.fail(&loc, name, format!("'{text}' is not a named index of refraction (e.g. bk7, water, air, diamond)"))
        });
    }
    let v = match p.float(name)? {
        Some(v) => v,
        None => named_ior(default).expect("a default from the table") as f64,
    };
    if !(v > 0.0 && v < 100.0) {
        return Err(p.fail(p.loc(), name, format!("must lie in (0, 100), got {v}")));
    }
    Ok(v)
}
