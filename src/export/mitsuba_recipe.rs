//! The Mitsuba 3 BSDF of a material the plain writers do not cover: one
//! whose parameters are textures (its recipe, `material::Textured`), one
//! seen through a normal or bump map, a one-sided one, the principled
//! BSDFs and blends. Parameters take the names `material::params` defines;
//! a texture is written inline where it is used, an image file copied
//! beside the meshes (the export's files never replace other contents).
//! Sidedness is written as the Mitsuba front-end reads it back: an opaque
//! two-sided material inside `twosided`, dielectrics and blends bare.

use super::ply::VertexAttribute;
use crate::material::params::{self, Spec};
use crate::material::{Material, Param, PrincipledRecipe, Textured, ThinRecipe};
use crate::math::Color;
use crate::scene::SceneParts;
use crate::texture::{Perturb, Texture};
use glam::Affine2;

/// Where image files go: the export's folder and its files so far.
pub(super) struct Files<'a> {
    pub dir: &'a str,
    pub files: &'a mut Vec<(String, Vec<u8>)>,
    /// The images copied so far: their source and their copy's name.
    pub copied: &'a mut Vec<(std::path::PathBuf, String)>,
}

/// Whether material `m` is written here rather than by the plain writers.
pub(super) fn needed(parts: &SceneParts, m: usize) -> bool {
    let t = &parts.texturing;
    matches!(t.materials.get(m), Some(Some(_)))
        || matches!(t.perturb.get(m), Some(Some(_)))
        || parts.one_sided.get(m) == Some(&true)
        || matches!(parts.materials[m], Material::Principled(_) | Material::PrincipledThin(_) | Material::Blend(_))
}

/// The materials a blend of material `m` names (they must be written too).
pub(super) fn parts_of(parts: &SceneParts, m: usize) -> Option<[u32; 2]> {
    match parts.texturing.materials.get(m) {
        Some(Some(Textured::Blend { first, second, .. })) => Some([*first, *second]),
        _ => None,
    }
}

/// Material `m`'s element, with id `id`; `plain` writes a material
/// without a recipe (with an id to be taken out).
pub(super) fn element(
    parts: &SceneParts,
    m: usize,
    id: &str,
    files: &mut Files,
    plain: &dyn Fn(&Material, &str) -> Result<String, String>,
) -> Result<String, String> {
    let one_sided = parts.one_sided.get(m) == Some(&true);
    let material = &parts.materials[m];
    let recipe = match parts.texturing.materials.get(m) {
        Some(Some(r)) => Some(r.clone()),
        _ => recipe_of(material),
    };
    let mut w = Writer { textures: &parts.texturing.textures, files };
    let core = match recipe {
        Some(r) => w.recipe(&r, one_sided)?,
        None if one_sided => {
            return Err("a one-sided material of this kind has no form in the Mitsuba export yet".into());
        }
        None => {
            let full = plain(material, "ID")?;
            full.trim().replacen(" id=\"ID\"", "", 1)
        }
    };
    let whole = match parts.texturing.perturb.get(m) {
        Some(Some(Perturb::BumpMap { texture, scale })) => format!(
            "<bsdf type=\"bumpmap\">{}<float name=\"scale\" value=\"{scale}\"/>{core}</bsdf>",
            w.texture(*texture, None)?
        ),
        Some(Some(Perturb::NormalMap(t))) => {
            format!("<bsdf type=\"normalmap\">{}{core}</bsdf>", w.texture(*t, Some("normalmap"))?)
        }
        _ => core,
    };
    Ok(format!("    {}\n", whole.replacen("<bsdf ", &format!("<bsdf id=\"{id}\" "), 1)))
}

/// A plain material the recipes describe (its parameters fixed).
fn recipe_of(m: &Material) -> Option<Textured> {
    let f = Param::Fixed;
    let n = |x: f32| Param::Fixed(Color::splat(x));
    Some(match m {
        Material::Lambertian { rho } => Textured::Diffuse { reflectance: f(*rho) },
        Material::Principled(p) => Textured::Principled(PrincipledRecipe::from_params(
            [
                f(p.base_color),
                n(p.roughness),
                n(p.anisotropic),
                n(p.metallic),
                n(p.spec_trans),
                n(p.spec_tint),
                n(p.sheen),
                n(p.sheen_tint),
                n(p.flatness),
                n(p.clearcoat),
                n(p.clearcoat_gloss),
            ],
            p.eta,
            p.rates,
        )),
        Material::PrincipledThin(p) => Textured::PrincipledThin(ThinRecipe::from_params(
            [
                f(p.base_color),
                n(p.roughness),
                n(p.anisotropic),
                n(p.spec_trans),
                n(p.eta),
                n(p.spec_tint),
                n(p.sheen),
                n(p.sheen_tint),
                n(p.flatness),
                n(p.diff_trans),
            ],
            p.rates,
        )),
        _ => return None,
    })
}

struct Writer<'t, 'f, 'a> {
    textures: &'t [Texture],
    files: &'f mut Files<'a>,
}

fn rgb(name: &str, c: Color) -> String {
    format!("<rgb name=\"{name}\" value=\"{}, {}, {}\"/>", c.x, c.y, c.z)
}

fn float(name: &str, x: f32) -> String {
    format!("<float name=\"{name}\" value=\"{x}\"/>")
}

fn two_sided(inner: String) -> String {
    format!("<bsdf type=\"twosided\">{inner}</bsdf>")
}

impl Writer<'_, '_, '_> {
    /// A parameter: a colour or a number where fixed, else its texture.
    fn param(&mut self, name: &str, p: Param, colour: bool) -> Result<String, String> {
        match p {
            Param::Fixed(c) if colour => Ok(rgb(name, c)),
            Param::Fixed(c) => Ok(float(name, c.x)),
            Param::Texture(t) => self.texture(t, Some(name)),
        }
    }

    /// Parameters by their definitions (reflectances as colours).
    fn params(&mut self, specs: &[Spec], values: &[Param]) -> Result<String, String> {
        let mut out = String::new();
        for (s, v) in specs.iter().zip(values) {
            out += &self.param(s.name, *v, s.kind == params::Kind::Reflectance)?;
        }
        Ok(out)
    }

    fn roughness(&mut self, distribution: crate::material::Distribution, u: Param, v: Param) -> Result<String, String> {
        let name = match distribution {
            crate::material::Distribution::Beckmann => "beckmann",
            crate::material::Distribution::Ggx => "ggx",
        };
        let alpha = if u == v {
            self.param("alpha", u, false)?
        } else {
            self.param("alpha_u", u, false)? + &self.param("alpha_v", v, false)?
        };
        Ok(format!("<string name=\"distribution\" value=\"{name}\"/>{alpha}"))
    }

    fn recipe(&mut self, r: &Textured, one_sided: bool) -> Result<String, String> {
        let sided = |x: String| if one_sided { x } else { two_sided(x) };
        Ok(match r {
            Textured::Diffuse { reflectance } => {
                sided(format!("<bsdf type=\"diffuse\">{}</bsdf>", self.param("reflectance", *reflectance, true)?))
            }
            Textured::Mask { opacity, reflectance } => format!(
                "<bsdf type=\"mask\">{}{}</bsdf>",
                self.param("opacity", *opacity, false)?,
                sided(format!("<bsdf type=\"diffuse\">{}</bsdf>", self.param("reflectance", *reflectance, true)?))
            ),
            Textured::DiffuseBlend { weight, first, second } => format!(
                "<bsdf type=\"blendbsdf\">{}{}{}</bsdf>",
                self.param("weight", *weight, false)?,
                sided(format!("<bsdf type=\"diffuse\">{}</bsdf>", self.param("reflectance", *first, true)?)),
                sided(format!("<bsdf type=\"diffuse\">{}</bsdf>", self.param("reflectance", *second, true)?))
            ),
            Textured::Conductor { eta, k, specular } => sided(format!(
                "<bsdf type=\"conductor\">{}{}{}</bsdf>",
                rgb("eta", *eta),
                rgb("k", *k),
                self.param("specular_reflectance", *specular, true)?
            )),
            Textured::RoughConductor { distribution, alpha_u, alpha_v, eta, k, specular } => sided(format!(
                "<bsdf type=\"roughconductor\">{}{}{}{}</bsdf>",
                self.roughness(*distribution, *alpha_u, *alpha_v)?,
                rgb("eta", *eta),
                rgb("k", *k),
                self.param("specular_reflectance", *specular, true)?
            )),
            Textured::RoughDielectric {
                distribution,
                alpha_u,
                alpha_v,
                int_ior,
                ext_ior,
                reflectance,
                transmittance,
            } => {
                format!(
                    "<bsdf type=\"roughdielectric\">{}{}{}{}{}</bsdf>",
                    self.roughness(*distribution, *alpha_u, *alpha_v)?,
                    float("int_ior", *int_ior),
                    float("ext_ior", *ext_ior),
                    self.param("specular_reflectance", *reflectance, true)?,
                    self.param("specular_transmittance", *transmittance, true)?
                )
            }
            Textured::Plastic { diffuse, specular, int_ior, ext_ior, nonlinear } => sided(format!(
                "<bsdf type=\"plastic\">{}{}{}{}<boolean name=\"nonlinear\" value=\"{nonlinear}\"/></bsdf>",
                self.param("diffuse_reflectance", *diffuse, true)?,
                self.param("specular_reflectance", *specular, true)?,
                float("int_ior", *int_ior),
                float("ext_ior", *ext_ior)
            )),
            Textured::RoughPlastic { distribution, alpha, diffuse, specular, int_ior, ext_ior, nonlinear } => {
                sided(format!(
                    "<bsdf type=\"roughplastic\">{}{}{}{}{}<boolean name=\"nonlinear\" value=\"{nonlinear}\"/></bsdf>",
                    self.roughness(
                        *distribution,
                        Param::Fixed(Color::splat(*alpha)),
                        Param::Fixed(Color::splat(*alpha))
                    )?,
                    self.param("diffuse_reflectance", *diffuse, true)?,
                    self.param("specular_reflectance", *specular, true)?,
                    float("int_ior", *int_ior),
                    float("ext_ior", *ext_ior)
                ))
            }
            Textured::Principled(p) => {
                if !one_sided && p.spec_trans != Param::Fixed(Color::ZERO) {
                    return Err("a two-sided principled material with specular transmission has no equivalent in \
                                Mitsuba 3 (its twosided takes no transmitting BSDF)"
                        .into());
                }
                let rates = p.rates.get();
                let mut x = self.params(params::PRINCIPLED, &p.params())? + &float("eta", p.eta);
                for (s, r) in params::PRINCIPLED_RATES.iter().zip(rates) {
                    x += &float(s.name, r);
                }
                sided(format!("<bsdf type=\"principled\">{x}</bsdf>"))
            }
            Textured::PrincipledThin(p) => {
                let mut x = self.params(params::PRINCIPLED_THIN, &p.params())?;
                for (s, r) in params::PRINCIPLED_THIN_RATES.iter().zip(p.rates.get()) {
                    x += &float(s.name, r);
                }
                format!("<bsdf type=\"principledthin\">{x}</bsdf>")
            }
            Textured::Blend { weight, first, second } => format!(
                "<bsdf type=\"blendbsdf\">{}<ref id=\"material{first}\"/><ref id=\"material{second}\"/></bsdf>",
                self.param("weight", *weight, false)?
            ),
        })
    }

    /// Texture `t` inline, named `name`; an image's file copied.
    fn texture(&mut self, t: u32, name: Option<&str>) -> Result<String, String> {
        let name = name.map_or(String::new(), |n| format!(" name=\"{n}\""));
        Ok(match &self.textures[t as usize] {
            Texture::Bitmap { image, to_uv } => {
                let Some((path, raw)) = &image.source else {
                    return Err("an image texture not read from a file has no form in the Mitsuba export".into());
                };
                let file = match self.files.copied.iter().find(|(p, _)| p == path) {
                    Some((_, file)) => file.clone(),
                    None => {
                        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("img");
                        let file = format!("{}/texture{:03}.{ext}", self.files.dir, self.files.copied.len());
                        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
                        self.files.files.push((file.clone(), bytes));
                        self.files.copied.push((path.clone(), file.clone()));
                        file
                    }
                };
                format!(
                    "<texture type=\"bitmap\"{name}><string name=\"filename\" value=\"{file}\"/><string \
                     name=\"filter_type\" value=\"{}\"/><string name=\"wrap_mode\" value=\"{}\"/><boolean \
                     name=\"raw\" value=\"{raw}\"/>{}</texture>",
                    image.filter_name(),
                    image.wrap_name(),
                    to_uv_xml(to_uv)
                )
            }
            Texture::Checkerboard { color0, color1, to_uv } => format!(
                "<texture type=\"checkerboard\"{name}>{}{}{}</texture>",
                rgb("color0", *color0),
                rgb("color1", *color1),
                to_uv_xml(to_uv)
            ),
            Texture::Constant(c) => format!("<texture type=\"rawconstant\"{name}>{}</texture>", rgb("value", *c)),
            // Every exported mesh carries the attribute (`mesh_attributes`).
            Texture::Attribute { scale, .. } => format!(
                "<texture type=\"mesh_attribute\"{name}><string name=\"name\" value=\"vertex_{}\"/>{}</texture>",
                attribute_name(t),
                float("scale", *scale)
            ),
        })
    }
}

/// The name of the PLY properties that carry attribute texture `t`.
fn attribute_name(t: u32) -> String {
    format!("attr{t}")
}

/// The scene's mesh attributes (`mesh_attribute` textures), as the
/// exported meshes carry them: each with its values per primitive (at its
/// three corners). A primitive without the attribute reads zero in
/// photonmap and in Mitsuba alike, so every mesh carries every attribute.
pub(super) fn mesh_attributes(textures: &[Texture]) -> Vec<(VertexAttribute, &[[Color; 3]])> {
    let grey = |c: &Color| c.x == c.y && c.y == c.z;
    (0..textures.len() as u32)
        .filter_map(|t| match &textures[t as usize] {
            Texture::Attribute { values, .. } => Some((
                VertexAttribute { name: attribute_name(t), grey: values.iter().flatten().all(grey) },
                &values[..],
            )),
            _ => None,
        })
        .collect()
}

/// A texture's `to_uv` as a 4x4 matrix (none for the identity).
fn to_uv_xml(m: &Affine2) -> String {
    if *m == Affine2::IDENTITY {
        return String::new();
    }
    let (x, y, t) = (m.matrix2.x_axis, m.matrix2.y_axis, m.translation);
    format!(
        "<transform name=\"to_uv\"><matrix value=\"{} {} 0 {} {} {} 0 {} 0 0 1 0 0 0 0 1\"/></transform>",
        x.x, y.x, t.x, x.y, y.y, t.y
    )
}
