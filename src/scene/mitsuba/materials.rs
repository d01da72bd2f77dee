//! `<bsdf>` plugins as photonmap's materials. Mitsuba's BSDFs reflect on
//! the front of a surface only (black behind the geometric normal) unless
//! wrapped in `twosided`; its dielectrics are two-sided by nature
//! (src/bsdfs/*.cpp). A shape with no BSDF is Mitsuba's default, a
//! diffuse reflectance of 0.5.

use super::props::Plugin;
use super::spectrum::Use;
use super::Builder;
use crate::material::indices;
use crate::material::params::{self, Spec};
use crate::material::{Distribution, Material, Param, Textured};
use crate::math::Color;
use crate::scene::file::SceneError;
use crate::texture::Perturb;

/// A material, its textured recipe where it reads textures, whether it is
/// one-sided, and how it bends the shading normal.
type Built = (Material, Option<Textured>, bool, Option<Perturb>);

/// How deep BSDFs may nest (blends, masks, twosided, bump maps).
const MAX_NESTING: u32 = 16;

impl Builder<'_> {
    /// The material index of a shape's BSDF (`None`: Mitsuba's default).
    pub(super) fn material(&mut self, bsdf: Option<&Plugin>) -> Result<u32, SceneError> {
        let key = bsdf.map_or(std::ptr::null(), |p| p.el as *const _);
        if let Some(&(_, m)) = self.material_cache.iter().find(|(k, _)| *k == key) {
            return Ok(m);
        }
        let grey = (Material::Lambertian { rho: Color::splat(0.5) }, None, true, None);
        let (material, textured, one_sided, perturb) = match bsdf {
            None => grey,
            Some(p) => match self.bsdf_of(p) {
                Ok(built) => built,
                Err(e) => {
                    self.substitute(p, "a grey diffuse BSDF (reflectance 0.5) stands in", e)?;
                    grey
                }
            },
        };
        let m = self.materials.len() as u32;
        self.origins.materials.push(bsdf.map(super::place).unwrap_or_default());
        self.materials.push(material);
        self.textured.push(textured);
        self.perturb.push(perturb);
        self.one_sided.push(one_sided);
        self.material_cache.push((key, m));
        Ok(m)
    }

    /// Parameter `name` of plugin `p` by its definition in `list`
    /// (`material::params`, shared with the TOML reader).
    fn defined(&mut self, p: &Plugin, list: &[Spec], name: &str) -> Result<Param, SceneError> {
        match params::find(list, name) {
            Some(s) => self.spec_param(p, s),
            None => Err(p.refuse(format!("'{name}' is not a parameter of the '{}' BSDF", p.kind))),
        }
    }

    fn bsdf_of(&mut self, p: &Plugin) -> Result<Built, SceneError> {
        if self.bsdf_nesting >= MAX_NESTING {
            return Err(p.refuse(format!("BSDFs nested more than {MAX_NESTING} deep (does one refer to itself?)")));
        }
        self.bsdf_nesting += 1;
        let built = self.bsdf_nested(p);
        self.bsdf_nesting -= 1;
        built
    }

    /// The material index of a BSDF inside a blend or mask: its own
    /// material (one-sided or not, textured or not), without a normal or
    /// bump map of its own.
    fn part(&mut self, q: &Plugin) -> Result<u32, SceneError> {
        let m = self.material(Some(q))?;
        if self.perturb[m as usize].is_some() {
            return Err(
                q.refuse("a normal or bump map inside a blend or mask is not supported (wrap the blend instead)")
            );
        }
        Ok(m)
    }

    fn bsdf_nested(&mut self, p: &Plugin) -> Result<Built, SceneError> {
        let recipe = match p.kind {
            "diffuse" => {
                let reflectance = self.defined(p, params::DIFFUSE, "reflectance")?;
                p.finish("reflectance")?;
                (Textured::Diffuse { reflectance }, true)
            }
            "blendbsdf" => {
                let weight = self.defined(p, params::BLEND, "weight")?;
                let inner = p.objects("bsdf")?;
                p.finish("weight, two nested <bsdf>")?;
                let [a, b] = &inner[..] else {
                    return Err(p.refuse(format!("a blendbsdf needs two nested <bsdf>, got {}", inner.len())));
                };
                // Two diffuse BSDFs of the same sidedness blend exactly into
                // one; any others are a blend the scene picks from per hit.
                match (self.diffuse_part(a)?, self.diffuse_part(b)?) {
                    (Some((first, one_a)), Some((second, one_b))) if one_a == one_b => {
                        (Textured::DiffuseBlend { weight, first, second }, one_a)
                    }
                    _ => (Textured::Blend { weight, first: self.part(a)?, second: self.part(b)? }, false),
                }
            }
            "normalmap" | "bumpmap" => {
                let perturb = if p.kind == "normalmap" {
                    match p.value("normalmap", Use::Unbounded)? {
                        Some(super::props::Value::Texture(t)) => Perturb::NormalMap(self.texture(&t)?),
                        Some(_) => return Err(p.fail(p.loc(), "normalmap", "must be a texture")),
                        None => return Err(p.refuse("a normalmap needs a 'normalmap' texture")),
                    }
                } else {
                    let scale = self.defined(p, params::BUMP_MAP, "scale")?.mean(&[]).x;
                    let textures = p.objects("texture")?;
                    let [t] = &textures[..] else {
                        return Err(p.refuse(format!("a bumpmap needs one nested <texture>, got {}", textures.len())));
                    };
                    Perturb::BumpMap { texture: self.texture(t)?, scale }
                };
                let inner = p.objects("bsdf")?;
                p.finish("normalmap, scale, one nested <texture> (bumpmap), one nested <bsdf>")?;
                let [q] = &inner[..] else {
                    return Err(p.refuse(format!("a {} needs one nested <bsdf>, got {}", p.kind, inner.len())));
                };
                let (material, textured, one_sided, nested) = self.bsdf_of(q)?;
                if nested.is_some() {
                    return Err(q.refuse("a normal or bump map inside another is not supported"));
                }
                return Ok((material, textured, one_sided, Some(perturb)));
            }
            "null" => {
                // Nothing there: light passes straight through (null.cpp), a
                // mask of opacity 0 on both sides.
                p.finish("nothing")?;
                let nothing = crate::material::Masked { opacity: 0.0, rho: Color::ZERO };
                return Ok((Material::Masked(nothing), None, false, None));
            }
            "mask" => {
                let opacity = self.defined(p, params::MASK, "opacity")?;
                let inner = p.objects("bsdf")?;
                p.finish("opacity, one nested <bsdf>")?;
                let [q] = &inner[..] else {
                    return Err(p.refuse(format!("a mask needs one nested <bsdf>, got {}", inner.len())));
                };
                match self.diffuse_part(q)? {
                    Some((reflectance, one)) => (Textured::Mask { opacity, reflectance }, one),
                    // Mitsuba's mask: the BSDF with chance `opacity`, else
                    // nothing there (null).
                    None => {
                        let null = self.plain(Material::Masked(crate::material::Masked { opacity: 0.0, rho: Color::ZERO }));
                        (Textured::Blend { weight: opacity, first: null, second: self.part(q)? }, false)
                    }
                }
            }
            "dielectric" => {
                let int = ior(p, params::ROUGH_DIELECTRIC, "int_ior")?;
                let ext = ior(p, params::ROUGH_DIELECTRIC, "ext_ior")?;
                for name in ["specular_reflectance", "specular_transmittance"] {
                    if let Some(c) = p.color(name, Use::Reflectance)? {
                        if c != Color::ONE {
                            return Err(p.fail(p.loc(), name, "only 1 (clear glass) is supported"));
                        }
                    }
                }
                p.finish("int_ior, ext_ior")?;
                return Ok((Material::glass((int / ext) as f32), None, false, None));
            }
            "conductor" | "roughconductor" => {
                let (eta, k) = complex_ior(p)?;
                let specular = self.defined(p, params::CONDUCTOR, "specular_reflectance")?;
                if p.kind == "conductor" {
                    p.finish("material, eta, k, specular_reflectance")?;
                    // eta 0 + 1i (material 'none', the export's mirror)
                    // reflects everything at every angle: the mirror.
                    if let (true, Param::Fixed(reflectance)) = (eta == Color::ZERO && k == Color::ONE, specular) {
                        return Ok((Material::Mirror { reflectance }, None, true, None));
                    }
                    (Textured::Conductor { eta, k, specular }, true)
                } else {
                    let (distribution, alpha_u, alpha_v) = self.microfacet(p, true)?;
                    p.finish(
                        "material, eta, k, specular_reflectance, distribution, alpha, alpha_u, alpha_v, sample_visible",
                    )?;
                    (Textured::RoughConductor { distribution, alpha_u, alpha_v, eta, k, specular }, true)
                }
            }
            "roughdielectric" | "thindielectric" => {
                let dielectric = params::ROUGH_DIELECTRIC;
                let (int, ext) = (ior(p, dielectric, "int_ior")?, ior(p, dielectric, "ext_ior")?);
                if int == ext {
                    return Err(p.refuse("the interior and exterior indices of refraction must differ"));
                }
                let reflectance = self.defined(p, params::ROUGH_DIELECTRIC, "specular_reflectance")?;
                let transmittance = self.defined(p, params::ROUGH_DIELECTRIC, "specular_transmittance")?;
                if p.kind == "thindielectric" {
                    let (Param::Fixed(r), Param::Fixed(t)) = (reflectance, transmittance) else {
                        return Err(p.refuse("a thindielectric's reflectance and transmittance must be colours"));
                    };
                    p.finish("int_ior, ext_ior, specular_reflectance, specular_transmittance")?;
                    return Ok((Material::thin_dielectric(int as f32, ext as f32, r, t), None, false, None));
                }
                let (distribution, alpha_u, alpha_v) = self.microfacet(p, true)?;
                p.finish(
                    "int_ior, ext_ior, specular_reflectance, specular_transmittance, distribution, alpha, alpha_u, \
                     alpha_v, sample_visible",
                )?;
                let (int_ior, ext_ior) = (int as f32, ext as f32);
                (
                    Textured::RoughDielectric { distribution, alpha_u, alpha_v, int_ior, ext_ior, reflectance, transmittance },
                    false,
                )
            }
            "plastic" | "roughplastic" => {
                let (int, ext) = (ior(p, params::PLASTIC, "int_ior")?, ior(p, params::PLASTIC, "ext_ior")?);
                if int == ext {
                    return Err(p.refuse("the interior and exterior indices of refraction must differ"));
                }
                let diffuse = self.defined(p, params::PLASTIC, "diffuse_reflectance")?;
                let specular = self.defined(p, params::PLASTIC, "specular_reflectance")?;
                let nonlinear = p.boolean("nonlinear", false)?;
                let (int_ior, ext_ior) = (int as f32, ext as f32);
                if p.kind == "plastic" {
                    p.finish("int_ior, ext_ior, diffuse_reflectance, specular_reflectance, nonlinear")?;
                    (Textured::Plastic { diffuse, specular, int_ior, ext_ior, nonlinear }, true)
                } else {
                    let (distribution, alpha, _) = self.microfacet(p, false)?;
                    let Param::Fixed(alpha) = alpha else {
                        return Err(p.refuse("a roughplastic's alpha must be a number (as in Mitsuba)"));
                    };
                    p.finish(
                        "int_ior, ext_ior, diffuse_reflectance, specular_reflectance, nonlinear, distribution, alpha, \
                         sample_visible",
                    )?;
                    let alpha = alpha.x;
                    (Textured::RoughPlastic { distribution, alpha, diffuse, specular, int_ior, ext_ior, nonlinear }, true)
                }
            }
            "principled" => (self.principled(p)?, true),
            "principledthin" => (self.principled_thin(p)?, false),
            "twosided" => {
                let inner = p.objects("bsdf")?;
                p.finish("one or two nested <bsdf>")?;
                return match &inner[..] {
                    [one] => {
                        let (m, t, _, perturb) = self.bsdf_of(one)?;
                        Ok((m, t.map(|t| self.two_sided(t)), false, perturb))
                    }
                    [_, two] => Err(two.refuse("a twosided BSDF with a different back BSDF is not supported yet")),
                    _ => Err(p.refuse("a twosided BSDF needs one nested <bsdf>")),
                };
            }
            k => {
                return Err(p.refuse(format!(
                    "the '{k}' BSDF is not supported yet (diffuse, dielectric, thindielectric, roughdielectric, \
                     conductor, roughconductor, plastic, roughplastic, principled, principledthin, blendbsdf, mask, null, normalmap, \
                     bumpmap and twosided are)"
                )))
            }
        };
        let (textured, one_sided) = recipe;
        // A stand-in with the same lobes until the scene holds the textures.
        let material = textured.typical(&[]);
        Ok((material, textured.reads_textures().then_some(textured), one_sided, None))
    }

    /// A diffuse BSDF's reflectance and sidedness; `None` for any other.
    fn diffuse_part(&mut self, q: &Plugin) -> Result<Option<(Param, bool)>, SceneError> {
        Ok(match self.bsdf_of(q)? {
            (_, Some(Textured::Diffuse { reflectance }), one, None) => Some((reflectance, one)),
            (Material::Lambertian { rho }, None, one, None) => Some((Param::Fixed(rho), one)),
            _ => None,
        })
    }

    /// A recipe seen from both sides: a blend's materials made two-sided
    /// too (copies, where they are one-sided), as Mitsuba's `twosided`
    /// shows its BSDF's front on both sides whatever is inside.
    fn two_sided(&mut self, t: Textured) -> Textured {
        let Textured::Blend { weight, first, second } = t else { return t };
        let mut both = |m: u32| -> u32 {
            let k = m as usize;
            if let Some(inner) = self.textured[k].clone() {
                if matches!(inner, Textured::Blend { .. }) {
                    let recipe = self.two_sided(inner);
                    return self.add(self.materials[k], Some(recipe), false);
                }
            }
            if !self.one_sided[k] {
                return m;
            }
            self.add(self.materials[k], self.textured[k].clone(), false)
        };
        let (first, second) = (both(first), both(second));
        Textured::Blend { weight, first, second }
    }

    fn add(&mut self, material: Material, textured: Option<Textured>, one_sided: bool) -> u32 {
        self.materials.push(material);
        self.textured.push(textured);
        self.perturb.push(None);
        self.one_sided.push(one_sided);
        self.materials.len() as u32 - 1
    }

    /// A material of no BSDF element (two-sided, plain).
    fn plain(&mut self, material: Material) -> u32 {
        self.add(material, None, false)
    }

    /// A microfacet distribution as Mitsuba reads it: `distribution`
    /// (beckmann by default, or ggx), `alpha` (0.1 by default) or, where
    /// `anisotropic`, `alpha_u` and `alpha_v` together, each a number or a
    /// texture; `sample_visible` is read and its sampling always used (it
    /// changes the noise, not the image).
    fn microfacet(&mut self, p: &Plugin, anisotropic: bool) -> Result<(Distribution, Param, Param), SceneError> {
        let distribution = match p.string("distribution")? {
            None => Distribution::Beckmann,
            Some((d, loc)) => match d.to_lowercase().as_str() {
                "beckmann" => Distribution::Beckmann,
                "ggx" => Distribution::Ggx,
                _ => return Err(p.fail(&loc, "distribution", format!("'{d}' is not beckmann or ggx"))),
            },
        };
        p.boolean("sample_visible", true)?;
        let mut read = |name: &str| -> Result<Option<Param>, SceneError> {
            if p.tag_of(name).is_none() {
                return Ok(None);
            }
            Ok(Some(self.defined(p, params::ROUGH_CONDUCTOR, name)?))
        };
        let alpha = read("alpha")?;
        let (au, av) = if anisotropic { (read("alpha_u")?, read("alpha_v")?) } else { (None, None) };
        let (au, av) = match (alpha, au, av) {
            (Some(a), None, None) => (a, a),
            (None, Some(u), Some(v)) => (u, v),
            (None, None, None) => {
                let alpha = Param::Fixed(Color::splat(crate::material::defaults::ALPHA));
                (alpha, alpha)
            }
            _ => return Err(p.refuse("give either alpha or both alpha_u and alpha_v")),
        };
        Ok((distribution, au, av))
    }
}

/// An index of refraction by its definition in `list`: a number in its
/// range or a name from Mitsuba's table (`material::indices`), else the
/// definition's default. Read as a double, as Mitsuba reads it: smooth
/// glass takes the ratio of two.
fn ior(p: &Plugin, list: &[Spec], name: &str) -> Result<f64, SceneError> {
    let spec = params::find(list, name).expect("an index the list defines");
    if p.tag_of(name) == Some("string") {
        let (text, loc) = p.string(name)?.expect("a string, looked at");
        return indices::index_named(&text).map(|v| v as f64).map_err(|m| p.fail(&loc, name, m));
    }
    let v = p.float(name)?.unwrap_or(spec.default as f64);
    spec.check(Color::splat(v as f32)).map_err(|m| p.fail(&p.named_loc(name), name, m))?;
    Ok(v)
}

/// A conductor's complex index: `eta` and `k`, or a named `material`
/// (`material::indices::complex_index`, shared with the TOML reader).
fn complex_ior(p: &Plugin) -> Result<(Color, Color), SceneError> {
    let value = |name: &str| -> Result<Option<Color>, SceneError> {
        let Some(c) = p.color(name, Use::Unbounded)? else { return Ok(None) };
        let spec = params::find(params::CONDUCTOR, name).expect("eta and k are defined");
        spec.check(c).map(Some).map_err(|m| p.fail(&p.named_loc(name), name, m))
    };
    let (eta, k) = (value("eta")?, value("k")?);
    let material = p.string("material")?;
    let loc = material.as_ref().map_or_else(|| p.loc().clone(), |(_, l)| l.clone());
    indices::complex_index(material.as_ref().map(|(m, _)| m.as_str()), eta, k).map_err(|m| p.fail(&loc, "material", m))
}
