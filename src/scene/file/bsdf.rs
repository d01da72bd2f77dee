//! The materials that take Mitsuba 3's names and parameters (`diffuse`,
//! `conductor`, `roughconductor`, `roughdielectric`, `thindielectric`,
//! `plastic`, `roughplastic`, `principled`, `principledthin`,
//! `blendbsdf`, `mask`, `bumpmap`, `normalmap`, `twosided`): each type's
//! fields are its list in `material::params`, the one definition the
//! Mitsuba front-end reads too; a field not in the list is refused at its
//! key. A colour or roughness may be a texture (by name or inline) where
//! Mitsuba allows one, a nested material a name or an inline table.
//! They are built as the Mitsuba front-end builds its plugins
//! (`scene/mitsuba/materials.rs`), so that a scene exported and read back
//! is the same scene.

use super::build::{At, Builder};
use super::defs::{Entry, V3};
use super::SceneError;
use crate::material::params::{self, Kind, Spec};
use crate::material::{Distribution, Masked, Material, Param, PrincipledRecipe, Textured, ThinRecipe};
use crate::math::Color;
use crate::texture::Perturb;
use std::ops::Range;
use toml::de::DeValue;
use toml::Spanned;

/// A material, its recipe where it reads textures, whether it is
/// one-sided, and how it bends the shading normal.
pub(super) type Built = (Material, Option<Textured>, bool, Option<Perturb>);

/// A typed table's fields, taken one by one by their definitions.
pub(super) struct Fields<'i> {
    pub(super) prefix: String,
    pub(super) kind: String,
    pub(super) kind_span: Range<usize>,
    items: Vec<(Spanned<String>, Spanned<DeValue<'i>>)>,
}

impl<'i> Fields<'i> {
    pub(super) fn take(&mut self, name: &str) -> Option<Spanned<DeValue<'i>>> {
        let i = self.items.iter().position(|(k, _)| k.get_ref() == name)?;
        Some(self.items.remove(i).1)
    }

    pub(super) fn has(&self, name: &str) -> bool {
        self.items.iter().any(|(k, _)| k.get_ref() == name)
    }

    pub(super) fn field(&self, name: &str) -> String {
        format!("{}.{name}", self.prefix)
    }
}

/// Nothing there: light passes straight through.
pub(super) const NOTHING: Material = Material::Masked(Masked { opacity: 0.0, rho: Color::ZERO });

impl<'a> Builder<'a> {
    /// The fields of `entry`, each one of `lists`' (else refused at its key).
    pub(super) fn fields(&self, entry: &mut Entry<'a>, lists: &[&[Spec]]) -> Result<Fields<'a>, SceneError> {
        let kind = entry.kind.get_ref().clone();
        let items = entry.fields();
        for (k, _) in &items {
            if lists.iter().any(|l| l.iter().any(|s| s.name == k.get_ref())) {
                continue;
            }
            let takes: Vec<String> = lists.iter().flat_map(|l| l.iter().map(|s| format!("`{}`", s.name))).collect();
            let message = if kind == "roughplastic" && (k.get_ref() == "alpha_u" || k.get_ref() == "alpha_v") {
                "roughplastic takes one isotropic `alpha` (as Mitsuba 3's, which refuses anisotropy)".to_string()
            } else {
                format!(
                    "unknown field `{}`: it does not apply to type \"{kind}\", which takes {}",
                    k.get_ref(),
                    takes.join(", ")
                )
            };
            return self.fail(k.span(), &format!("{}.{}", entry.field, k.get_ref()), message);
        }
        Ok(Fields { prefix: entry.field.clone(), kind, kind_span: entry.kind.span(), items })
    }

    fn missing<T>(&self, f: &Fields, name: &str) -> Result<T, SceneError> {
        self.fail(
            f.kind_span.clone(),
            &f.field(name),
            format!("missing field `{name}` (required for type \"{}\")", f.kind),
        )
    }

    /// A parameter by its definition: its default where absent, a number
    /// or colour in its range, or a texture where it may be one.
    pub(super) fn param(&mut self, f: &mut Fields<'a>, s: &Spec) -> Result<Param, SceneError> {
        let field = f.field(s.name);
        let Some(v) = f.take(s.name) else {
            if s.default.is_nan() {
                return self.missing(f, s.name);
            }
            return Ok(Param::Fixed(s.default_color()));
        };
        let span = v.span();
        let colour = matches!(s.kind, Kind::Reflectance | Kind::Color);
        let c = match v.get_ref() {
            DeValue::Integer(_) | DeValue::Float(_) => {
                let x: f32 = self.src.read(v, &field)?;
                self.finite(&At { value: &[x; 3], span: span.clone(), field: field.clone() })?
            }
            DeValue::Array(_) if colour => {
                let a: V3 = self.src.read(v, &field)?;
                self.finite(&At { value: &a, span: span.clone(), field: field.clone() })?
            }
            DeValue::String(_) if s.kind == Kind::Index => {
                let name: String = self.src.read(v, &field)?;
                let x = crate::material::indices::index_named(&name).map_err(|m| self.src.error(span, field, m))?;
                return Ok(Param::Fixed(Color::splat(x)));
            }
            DeValue::String(_) | DeValue::Table(_) if s.texture => {
                return Ok(Param::Texture(self.texture_value(v, field)?));
            }
            other => {
                let what = match (colour, s.texture) {
                    (true, true) => "a colour [r, g, b], a number or a texture (its name or an inline table)",
                    (true, false) => "a colour [r, g, b] or a number",
                    (false, true) => "a number or a texture (its name or an inline table)",
                    (false, false) if s.kind == Kind::Index => "a number or the name of an index (e.g. \"bk7\")",
                    (false, false) => "a number",
                };
                return self.fail(span, &field, format!("invalid type: {}, expected {what}", other.type_str()));
            }
        };
        s.check(c).map_err(|m| self.src.error(span, field, m))?;
        Ok(Param::Fixed(c))
    }

    /// A parameter that no texture gives: its value.
    fn fixed(&mut self, f: &mut Fields<'a>, s: &Spec) -> Result<Color, SceneError> {
        Ok(match self.param(f, s)? {
            Param::Fixed(c) => c,
            // A spec that takes no texture gives none.
            Param::Texture(_) => s.default_color(),
        })
    }

    pub(super) fn flag(&self, f: &mut Fields<'a>, name: &str) -> Result<bool, SceneError> {
        let field = f.field(name);
        f.take(name).map_or(Ok(false), |v| self.src.read(v, &field))
    }

    /// One of a choice's names, or `None` where absent.
    pub(super) fn choice(&self, f: &mut Fields<'a>, s: &Spec) -> Result<Option<String>, SceneError> {
        let field = f.field(s.name);
        let Some(v) = f.take(s.name) else { return Ok(None) };
        let span = v.span();
        let text: String = self.src.read(v, &field)?;
        let Kind::Choice(names) = s.kind else { return Ok(Some(text)) };
        if !names.contains(&text.as_str()) {
            return self.fail(span, &field, format!("unknown {} \"{text}\" ({})", s.name, names.join(", ")));
        }
        Ok(Some(text))
    }

    /// A nested material: a name or an inline table.
    fn nested(&mut self, v: Spanned<DeValue<'a>>, field: String) -> Result<u32, SceneError> {
        let span = v.span();
        match v.get_ref() {
            DeValue::String(_) => {
                let name: String = self.src.read(v, &field)?;
                self.material_ref(&Spanned::new(span, name), field)
            }
            DeValue::Table(_) => {
                let mut entry = Entry::new(&self.src, field.clone(), v)?;
                let built = self.material(&mut entry)?;
                let place = self.place(entry.kind.span(), field);
                Ok(self.push_material(built, place))
            }
            other => self.fail(
                span,
                &field,
                format!("invalid type: {}, expected a material's name or an inline material table", other.type_str()),
            ),
        }
    }

    fn nested_field(&mut self, f: &mut Fields<'a>, name: &str) -> Result<u32, SceneError> {
        match f.take(name) {
            Some(v) => self.nested(v, f.field(name)),
            None => self.missing(f, name),
        }
    }

    /// The material of a type `material::params` defines, or `None` for
    /// another type.
    pub(super) fn bsdf(&mut self, entry: &mut Entry<'a>) -> Result<Option<Built>, SceneError> {
        let kind = entry.kind.get_ref().clone();
        let lists: Vec<&'static [Spec]> = match kind.as_str() {
            "principled" => vec![params::PRINCIPLED, params::PRINCIPLED_ETA, params::PRINCIPLED_RATES],
            "principledthin" => vec![params::PRINCIPLED_THIN, params::PRINCIPLED_THIN_RATES],
            k => match params::of(k) {
                Some(list) => vec![list],
                None => return Ok(None),
            },
        };
        let mut f = self.fields(entry, &lists)?;
        let specs = lists[0];
        let spec = |name: &str| params::find(specs, name).copied().unwrap_or(specs[0]);
        let recipe = match kind.as_str() {
            "diffuse" => (Textured::Diffuse { reflectance: self.param(&mut f, &spec("reflectance"))? }, false),
            "conductor" | "roughconductor" => {
                let (eta, k) = self.complex_index(&mut f, specs)?;
                let specular = self.param(&mut f, &spec("specular_reflectance"))?;
                if kind == "conductor" {
                    (Textured::Conductor { eta, k, specular }, false)
                } else {
                    let (distribution, alpha_u, alpha_v) = self.roughness(&mut f, specs, true)?;
                    (Textured::RoughConductor { distribution, alpha_u, alpha_v, eta, k, specular }, false)
                }
            }
            "roughdielectric" => {
                let (int_ior, ext_ior) = self.indices(&mut f, specs, true)?;
                let reflectance = self.param(&mut f, &spec("specular_reflectance"))?;
                let transmittance = self.param(&mut f, &spec("specular_transmittance"))?;
                let (distribution, alpha_u, alpha_v) = self.roughness(&mut f, specs, true)?;
                let t = Textured::RoughDielectric {
                    distribution,
                    alpha_u,
                    alpha_v,
                    int_ior,
                    ext_ior,
                    reflectance,
                    transmittance,
                };
                (t, false)
            }
            "thindielectric" => {
                let (int_ior, ext_ior) = self.indices(&mut f, specs, true)?;
                let r = self.fixed(&mut f, &spec("specular_reflectance"))?;
                let t = self.fixed(&mut f, &spec("specular_transmittance"))?;
                return Ok(Some((Material::thin_dielectric(int_ior, ext_ior, r, t), None, false, None)));
            }
            "plastic" | "roughplastic" => {
                let (int_ior, ext_ior) = self.indices(&mut f, specs, kind == "roughplastic")?;
                let diffuse = self.param(&mut f, &spec("diffuse_reflectance"))?;
                let specular = self.param(&mut f, &spec("specular_reflectance"))?;
                let nonlinear = self.flag(&mut f, "nonlinear")?;
                if kind == "plastic" {
                    (Textured::Plastic { diffuse, specular, int_ior, ext_ior, nonlinear }, false)
                } else {
                    let (distribution, alpha, _) = self.roughness(&mut f, specs, false)?;
                    let alpha = alpha.mean(&[]).x;
                    (
                        Textured::RoughPlastic { distribution, alpha, diffuse, specular, int_ior, ext_ior, nonlinear },
                        false,
                    )
                }
            }
            "principled" => {
                let has_spec_trans = match f.items.iter().find(|(k, _)| k.get_ref() == "spec_trans") {
                    Some((_, v)) => {
                        !matches!(v.get_ref(), DeValue::Integer(i) if i.as_str() == "0")
                            && !matches!(v.get_ref(), DeValue::Float(x) if x.as_str().parse::<f32>() == Ok(0.0))
                    }
                    None => false,
                };
                if f.has("eta") && f.has("specular") {
                    let v = f.take("specular").map_or(f.kind_span.clone(), |v| v.span());
                    return self.fail(
                        v,
                        &f.field("specular"),
                        "give either `eta` or `specular`, not both (as in Mitsuba)",
                    );
                }
                let number = |b: &mut Self, f: &mut Fields<'a>, s: &Spec| -> Result<Option<f32>, SceneError> {
                    Ok(if f.has(s.name) { Some(b.fixed(f, s)?.x) } else { None })
                };
                let eta = number(self, &mut f, &params::PRINCIPLED_ETA[0])?;
                let specular = number(self, &mut f, &params::PRINCIPLED_ETA[1])?;
                let eta = params::principled_eta(eta, specular, has_spec_trans);
                let p = self.params::<11>(&mut f, params::PRINCIPLED)?;
                let rates = self.rates(&mut f, params::PRINCIPLED_RATES)?;
                // One-sided, as Mitsuba's plugin (its twosided takes no
                // transmitting BSDF): `twosided` makes an opaque one two-sided.
                (Textured::Principled(PrincipledRecipe::from_params(p, eta, rates)), true)
            }
            "principledthin" => {
                let p = self.params::<10>(&mut f, params::PRINCIPLED_THIN)?;
                let rates = self.rates(&mut f, params::PRINCIPLED_THIN_RATES)?;
                (Textured::PrincipledThin(ThinRecipe::from_params(p, rates)), false)
            }
            "blendbsdf" => {
                let weight = self.param(&mut f, &spec("weight"))?;
                let field = f.field("materials");
                let Some(v) = f.take("materials") else { return self.missing(&f, "materials") };
                let span = v.span();
                let DeValue::Array(items) = v.into_inner() else {
                    return self.fail(span, &field, "must be an array of two materials (names or inline tables)");
                };
                if items.len() != 2 {
                    return self.fail(span, &field, format!("a blend takes two materials, got {}", items.len()));
                }
                let mut parts = [0u32; 2];
                for (j, item) in items.into_iter().enumerate() {
                    parts[j] = self.nested(item, format!("{field}[{j}]"))?;
                    self.unperturbed(parts[j], span.clone(), &field)?;
                }
                // Two diffuse materials of the same sidedness blend exactly
                // into one (as the Mitsuba front-end reads them).
                match (self.diffuse_of(parts[0]), self.diffuse_of(parts[1])) {
                    (Some((first, one_a)), Some((second, one_b))) if one_a == one_b => {
                        (Textured::DiffuseBlend { weight, first, second }, one_a)
                    }
                    _ => (Textured::Blend { weight, first: parts[0], second: parts[1] }, false),
                }
            }
            "mask" => {
                let opacity = self.param(&mut f, &spec("opacity"))?;
                let inner = self.nested_field(&mut f, "material")?;
                self.unperturbed(inner, f.kind_span.clone(), &f.field("material"))?;
                match self.diffuse_of(inner) {
                    Some((reflectance, one)) => (Textured::Mask { opacity, reflectance }, one),
                    None => {
                        let null = self.push_material((NOTHING, None, false, None), Default::default());
                        (Textured::Blend { weight: opacity, first: null, second: inner }, false)
                    }
                }
            }
            "bumpmap" | "normalmap" => {
                let texture_name = if kind == "bumpmap" { "texture" } else { "normalmap" };
                let texture = match self.param(&mut f, &spec(texture_name))? {
                    Param::Texture(t) => t,
                    Param::Fixed(_) => return self.missing(&f, texture_name),
                };
                let perturb = if kind == "bumpmap" {
                    let scale = self.fixed(&mut f, &spec("scale"))?.x;
                    Perturb::BumpMap { texture, scale }
                } else {
                    Perturb::NormalMap(texture)
                };
                let inner = self.nested_field(&mut f, "material")?;
                let i = inner as usize;
                if self.perturb[i].is_some() {
                    let field = f.field("material");
                    return self.fail(
                        f.kind_span.clone(),
                        &field,
                        "a normal or bump map inside another is not supported",
                    );
                }
                return Ok(Some((self.materials[i], self.textured[i].clone(), self.one_sided[i], Some(perturb))));
            }
            "twosided" => {
                let inner = self.nested_field(&mut f, "material")?;
                let i = inner as usize;
                let t = self.textured[i].clone().map(|t| self.two_sided(t));
                return Ok(Some((self.materials[i], t, false, self.perturb[i])));
            }
            _ => return Ok(None),
        };
        let (textured, one_sided) = recipe;
        // A stand-in with the same lobes until the scene holds the textures.
        let material = textured.typical(&[]);
        Ok(Some((material, textured.reads_textures().then_some(textured), one_sided, None)))
    }

    /// A diffuse material's reflectance and sidedness; `None` for any other.
    fn diffuse_of(&self, m: u32) -> Option<(Param, bool)> {
        let i = m as usize;
        if self.perturb[i].is_some() {
            return None;
        }
        match (self.materials[i], self.textured[i].clone()) {
            (_, Some(Textured::Diffuse { reflectance })) => Some((reflectance, self.one_sided[i])),
            (Material::Lambertian { rho }, None) => Some((Param::Fixed(rho), self.one_sided[i])),
            _ => None,
        }
    }

    /// A blend's or mask's material may not bend the normal itself.
    fn unperturbed(&self, m: u32, span: Range<usize>, field: &str) -> Result<(), SceneError> {
        if self.perturb[m as usize].is_some() {
            return self.fail(
                span,
                field,
                "a normal or bump map inside a blend or mask is not supported (wrap the blend instead)",
            );
        }
        Ok(())
    }

    /// A recipe seen from both sides: a blend's one-sided materials copied
    /// as two-sided ones (as the Mitsuba front-end's `twosided`).
    fn two_sided(&mut self, t: Textured) -> Textured {
        let Textured::Blend { weight, first, second } = t else { return t };
        let both = |b: &mut Self, m: u32| -> u32 {
            let k = m as usize;
            if let Some(inner @ Textured::Blend { .. }) = b.textured[k].clone() {
                let recipe = b.two_sided(inner);
                return b.push_material((b.materials[k], Some(recipe), false, None), Default::default());
            }
            if !b.one_sided[k] {
                return m;
            }
            b.push_material((b.materials[k], b.textured[k].clone(), false, None), Default::default())
        };
        let (first, second) = (both(self, first), both(self, second));
        Textured::Blend { weight, first, second }
    }

    fn params<const N: usize>(&mut self, f: &mut Fields<'a>, specs: &[Spec]) -> Result<[Param; N], SceneError> {
        let mut out = [Param::Fixed(Color::ZERO); N];
        for (o, s) in out.iter_mut().zip(specs) {
            *o = self.param(f, s)?;
        }
        Ok(out)
    }

    fn rates(&mut self, f: &mut Fields<'a>, specs: &[Spec]) -> Result<crate::material::disney::Rates, SceneError> {
        let mut rates = [1.0f32; 4];
        for (r, s) in rates.iter_mut().zip(specs) {
            *r = self.fixed(f, s)?.x;
        }
        match crate::material::disney::Rates::intern(rates) {
            Some(r) => Ok(r),
            None => self.fail(f.kind_span.clone(), &f.prefix, "more than 255 different sets of sampling rates"),
        }
    }

    /// A conductor's (eta, k): a named `material` or `eta` and `k`
    /// (`material::indices::complex_index`, as the Mitsuba front-end).
    fn complex_index(&mut self, f: &mut Fields<'a>, specs: &[Spec]) -> Result<(Color, Color), SceneError> {
        let spec = |n: &str| params::find(specs, n).copied().unwrap_or(specs[0]);
        let span =
            f.items.iter().find(|(k, _)| k.get_ref() == "material").map_or(f.kind_span.clone(), |(_, v)| v.span());
        let field = f.field("material");
        let material = self.choice(f, &spec("material"))?;
        let mut given = |b: &mut Self, n: &str| -> Result<Option<Color>, SceneError> {
            if !f.has(n) {
                return Ok(None);
            }
            b.fixed(f, &spec(n)).map(Some)
        };
        let (eta, k) = (given(self, "eta")?, given(self, "k")?);
        crate::material::indices::complex_index(material.as_deref(), eta, k).map_err(|m| self.src.error(span, field, m))
    }

    /// The interior and exterior indices, which must differ where an
    /// interface between them is rendered.
    fn indices(&mut self, f: &mut Fields<'a>, specs: &[Spec], differ: bool) -> Result<(f32, f32), SceneError> {
        let span = ["int_ior", "ext_ior"]
            .iter()
            .find_map(|n| f.items.iter().find(|(k, _)| k.get_ref() == *n).map(|(_, v)| v.span()))
            .unwrap_or(f.kind_span.clone());
        let spec = |n: &str| params::find(specs, n).copied().unwrap_or(specs[0]);
        let i = self.fixed(f, &spec("int_ior"))?.x;
        let e = self.fixed(f, &spec("ext_ior"))?.x;
        if differ && i == e {
            return self.fail(span, &f.field("int_ior"), format!("int_ior and ext_ior must differ, both are {i}"));
        }
        Ok((i, e))
    }

    /// The distribution and (alpha_u, alpha_v): `alpha` alone, or both of
    /// `alpha_u` and `alpha_v` where `anisotropic`; Mitsuba's default
    /// Beckmann, alpha 0.1.
    fn roughness(
        &mut self,
        f: &mut Fields<'a>,
        specs: &[Spec],
        anisotropic: bool,
    ) -> Result<(Distribution, Param, Param), SceneError> {
        let spec = |n: &str| params::find(specs, n).copied().unwrap_or(specs[0]);
        let dist = match self.choice(f, &spec("distribution"))?.as_deref() {
            Some("ggx") => Distribution::Ggx,
            Some(_) => Distribution::Beckmann,
            None => crate::material::defaults::DISTRIBUTION,
        };
        let (a, u, v) = (f.has("alpha"), anisotropic && f.has("alpha_u"), anisotropic && f.has("alpha_v"));
        let span = |f: &Fields, n: &str| {
            f.items.iter().find(|(k, _)| k.get_ref() == n).map_or(f.kind_span.clone(), |(_, v)| v.span())
        };
        match (a, u, v) {
            (true, false, false) => {
                let alpha = self.param(f, &spec("alpha"))?;
                Ok((dist, alpha, alpha))
            }
            (false, true, true) => Ok((dist, self.param(f, &spec("alpha_u"))?, self.param(f, &spec("alpha_v"))?)),
            (false, false, false) => {
                let alpha = Param::Fixed(Color::splat(crate::material::defaults::ALPHA));
                Ok((dist, alpha, alpha))
            }
            (true, _, _) => {
                self.fail(span(f, "alpha"), &f.field("alpha"), "give either `alpha` or `alpha_u` and `alpha_v`")
            }
            _ => {
                let n = if u { "alpha_u" } else { "alpha_v" };
                let message = format!("`alpha_u` and `alpha_v` go together (type \"{}\")", f.kind);
                self.fail(span(f, n), &f.field(n), message)
            }
        }
    }
}
