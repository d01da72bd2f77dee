//! `<bsdf>` plugins as photonmap's materials. Mitsuba's BSDFs reflect on
//! the front of a surface only (black behind the geometric normal) unless
//! wrapped in `twosided`; its dielectrics are two-sided by nature
//! (src/bsdfs/*.cpp). A shape with no BSDF is Mitsuba's default, a
//! diffuse reflectance of 0.5.

use super::props::Plugin;
use super::spectrum::{named_ior, Use};
use super::Builder;
use crate::material::{Distribution, Material};
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
        "conductor" | "roughconductor" => {
            let (eta, k) = complex_ior(p)?;
            let specular = p.color("specular_reflectance", Use::Reflectance)?.unwrap_or(Color::ONE);
            let specular = bounded(p, "specular_reflectance", specular)?;
            if p.kind == "conductor" {
                p.finish("material, eta, k, specular_reflectance")?;
                return Ok((Material::conductor(eta, k, specular), true));
            }
            let (distribution, au, av) = microfacet(p, true)?;
            p.finish("material, eta, k, specular_reflectance, distribution, alpha, alpha_u, alpha_v, sample_visible")?;
            Ok((Material::rough_conductor(distribution, au, av, eta, k, specular), true))
        }
        "roughdielectric" | "thindielectric" => {
            let (int, ext) = (ior(p, "int_ior", "bk7")?, ior(p, "ext_ior", "air")?);
            if int == ext {
                return Err(p.refuse("the interior and exterior indices of refraction must differ"));
            }
            let r = p.color("specular_reflectance", Use::Reflectance)?.unwrap_or(Color::ONE);
            let t = p.color("specular_transmittance", Use::Reflectance)?.unwrap_or(Color::ONE);
            let (r, t) = (bounded(p, "specular_reflectance", r)?, bounded(p, "specular_transmittance", t)?);
            if p.kind == "thindielectric" {
                p.finish("int_ior, ext_ior, specular_reflectance, specular_transmittance")?;
                return Ok((Material::thin_dielectric(int as f32, ext as f32, r, t), false));
            }
            let (distribution, au, av) = microfacet(p, true)?;
            p.finish(
                "int_ior, ext_ior, specular_reflectance, specular_transmittance, distribution, alpha, alpha_u, \
                 alpha_v, sample_visible",
            )?;
            Ok((Material::rough_dielectric(distribution, au, av, int as f32, ext as f32, r, t), false))
        }
        "plastic" | "roughplastic" => {
            let (int, ext) = (ior(p, "int_ior", "polypropylene")?, ior(p, "ext_ior", "air")?);
            if int == ext {
                return Err(p.refuse("the interior and exterior indices of refraction must differ"));
            }
            let diffuse = p.color("diffuse_reflectance", Use::Reflectance)?.unwrap_or(Color::splat(0.5));
            let diffuse = bounded(p, "diffuse_reflectance", diffuse)?;
            let specular = p.color("specular_reflectance", Use::Reflectance)?.unwrap_or(Color::ONE);
            let specular = bounded(p, "specular_reflectance", specular)?;
            let nonlinear = p.boolean("nonlinear", false)?;
            if p.kind == "plastic" {
                p.finish("int_ior, ext_ior, diffuse_reflectance, specular_reflectance, nonlinear")?;
                return Ok((Material::plastic(diffuse, specular, int as f32, ext as f32, nonlinear), true));
            }
            let (distribution, au, _) = microfacet(p, false)?;
            p.finish(
                "int_ior, ext_ior, diffuse_reflectance, specular_reflectance, nonlinear, distribution, alpha, \
                 sample_visible",
            )?;
            Ok((Material::rough_plastic(distribution, au, diffuse, specular, int as f32, ext as f32, nonlinear), true))
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
            "the '{k}' BSDF is not supported yet (diffuse, dielectric, thindielectric, roughdielectric, conductor, \
             roughconductor, plastic, roughplastic and twosided are)"
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

/// A conductor's complex index: `eta` and `k`, or a named `material`
/// (conductors.rs; 'none': a perfect mirror, eta 0 + 1i).
fn complex_ior(p: &Plugin) -> Result<(Color, Color), SceneError> {
    let eta = p.color("eta", Use::Unbounded)?;
    let k = p.color("k", Use::Unbounded)?;
    let material = p.string("material")?;
    match (material, eta, k) {
        (Some((m, loc)), Some(_), _) | (Some((m, loc)), _, Some(_)) if m != "none" => {
            Err(p.fail(&loc, "material", format!("give either eta and k or a material ('{m}'), not both")))
        }
        (Some((m, loc)), None, None) if m != "none" => super::conductors::named_conductor(&m).ok_or_else(|| {
            p.fail(&loc, "material", format!("'{m}' is not a conductor Mitsuba names (e.g. Au, Ag, Al, Cu, Cr)"))
        }),
        (_, eta, k) => Ok((eta.unwrap_or(Color::ZERO), k.unwrap_or(Color::ONE))),
    }
}

/// A microfacet distribution as Mitsuba reads it: `distribution`
/// (beckmann by default, or ggx), `alpha` (0.1 by default) or, where
/// `anisotropic`, `alpha_u` and `alpha_v` together; `sample_visible` is
/// read and its sampling always used (it changes the noise, not the image).
fn microfacet(p: &Plugin, anisotropic: bool) -> Result<(Distribution, f32, f32), SceneError> {
    let distribution = match p.string("distribution")? {
        None => Distribution::Beckmann,
        Some((d, loc)) => match d.to_lowercase().as_str() {
            "beckmann" => Distribution::Beckmann,
            "ggx" => Distribution::Ggx,
            _ => return Err(p.fail(&loc, "distribution", format!("'{d}' is not beckmann or ggx"))),
        },
    };
    p.boolean("sample_visible", true)?;
    let alpha = p.float("alpha")?;
    let (au, av) = if anisotropic { (p.float("alpha_u")?, p.float("alpha_v")?) } else { (None, None) };
    let (au, av) = match (alpha, au, av) {
        (Some(a), None, None) => (a, a),
        (None, Some(u), Some(v)) => (u, v),
        (None, None, None) => (0.1, 0.1),
        _ => return Err(p.refuse("give either alpha or both alpha_u and alpha_v")),
    };
    for (name, a) in [("alpha", au), ("alpha", av)] {
        if !(0.0..=10.0).contains(&a) {
            return Err(p.fail(p.loc(), name, format!("must lie in [0, 10], got {a}")));
        }
    }
    Ok((distribution, au as f32, av as f32))
}
