//! The parameters of the materials that take Mitsuba 3's names, defined
//! once for both scene front-ends: each type's parameters with their
//! names, defaults, ranges and whether a texture may give them
//! (Mitsuba 3's src/bsdfs/*.cpp and its documentation). The TOML reader
//! takes a type's fields from its list (and refuses any other), the XML
//! reader reads Mitsuba's plugins by the same names; both check a value
//! with [`Spec::check`].

use crate::math::Color;

/// What values a parameter takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A colour within [0, 1] per channel (a number: grey), or a texture.
    Reflectance,
    /// A colour of any size ≥ 0 (a complex index's parts).
    Color,
    /// A number within [0, hi].
    Weight(f32),
    /// A number within [-hi, hi].
    Signed(f32),
    /// A roughness, within [0, 10].
    Alpha,
    /// An index of refraction, within (0, 100), or its name
    /// ([`super::indices::NAMED_IOR`]).
    Index,
    /// A conductor's name ([`super::conductors`], or `none`), which
    /// stands for its `eta` and `k` ([`super::indices::complex_index`]).
    Conductor,
    /// A sampling rate: above 0.
    Rate,
    /// `true` or `false`.
    Flag,
    /// One of the names listed.
    Choice(&'static [&'static str]),
    /// A texture only (a normal map, a bump map's heights).
    TextureOnly,
    /// A material nested in this one (by name or inline).
    Material,
    /// Two nested materials.
    Materials,
    /// A file name (relative to the scene file).
    File,
    /// A name (a mesh attribute's: `vertex_…` or `face_…`).
    Name,
    /// A transform (a texture's `to_uv`: its 2D part).
    Transform,
}

/// One parameter of a material type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    pub name: &'static str,
    pub kind: Kind,
    /// Where a value is a number or a colour: its default (in every
    /// channel); NaN where the parameter is required or has no number.
    pub default: f32,
    /// Whether a texture may give it (where Mitsuba allows one).
    pub texture: bool,
}

const fn spec(name: &'static str, kind: Kind, default: f32, texture: bool) -> Spec {
    Spec { name, kind, default, texture }
}

const DISTRIBUTIONS: &[&str] = &["beckmann", "ggx"];

const fn distribution() -> Spec {
    spec("distribution", Kind::Choice(DISTRIBUTIONS), f32::NAN, false)
}
const fn alpha(name: &'static str) -> Spec {
    spec(name, Kind::Alpha, super::defaults::ALPHA, true)
}
const fn reflectance(name: &'static str, default: f32) -> Spec {
    spec(name, Kind::Reflectance, default, true)
}
const fn index(name: &'static str, default: f32) -> Spec {
    spec(name, Kind::Index, default, false)
}
const fn weight(name: &'static str, default: f32) -> Spec {
    spec(name, Kind::Weight(1.0), default, true)
}
const fn rate(name: &'static str) -> Spec {
    spec(name, Kind::Rate, 1.0, false)
}

use super::defaults::{CONDUCTOR_ETA, CONDUCTOR_K, DIELECTRIC_INT_IOR, DIFFUSE_REFLECTANCE, EXT_IOR, PLASTIC_INT_IOR};

/// Mitsuba's `diffuse`.
pub const DIFFUSE: &[Spec] = &[reflectance("reflectance", 0.5)];
pub const CONDUCTOR: &[Spec] = &[
    spec("material", Kind::Conductor, f32::NAN, false),
    spec("eta", Kind::Color, CONDUCTOR_ETA, false),
    spec("k", Kind::Color, CONDUCTOR_K, false),
    reflectance("specular_reflectance", 1.0),
];
pub const ROUGH_CONDUCTOR: &[Spec] = &[
    spec("material", Kind::Conductor, f32::NAN, false),
    spec("eta", Kind::Color, CONDUCTOR_ETA, false),
    spec("k", Kind::Color, CONDUCTOR_K, false),
    reflectance("specular_reflectance", 1.0),
    distribution(),
    alpha("alpha"),
    alpha("alpha_u"),
    alpha("alpha_v"),
];
pub const ROUGH_DIELECTRIC: &[Spec] = &[
    index("int_ior", DIELECTRIC_INT_IOR),
    index("ext_ior", EXT_IOR),
    reflectance("specular_reflectance", 1.0),
    reflectance("specular_transmittance", 1.0),
    distribution(),
    alpha("alpha"),
    alpha("alpha_u"),
    alpha("alpha_v"),
];
pub const THIN_DIELECTRIC: &[Spec] = &[
    index("int_ior", DIELECTRIC_INT_IOR),
    index("ext_ior", EXT_IOR),
    spec("specular_reflectance", Kind::Reflectance, 1.0, false),
    spec("specular_transmittance", Kind::Reflectance, 1.0, false),
];
pub const PLASTIC: &[Spec] = &[
    index("int_ior", PLASTIC_INT_IOR),
    index("ext_ior", EXT_IOR),
    reflectance("diffuse_reflectance", DIFFUSE_REFLECTANCE),
    reflectance("specular_reflectance", 1.0),
    spec("nonlinear", Kind::Flag, f32::NAN, false),
];
/// Isotropic only, as Mitsuba's; its alpha a number.
pub const ROUGH_PLASTIC: &[Spec] = &[
    index("int_ior", PLASTIC_INT_IOR),
    index("ext_ior", EXT_IOR),
    reflectance("diffuse_reflectance", DIFFUSE_REFLECTANCE),
    reflectance("specular_reflectance", 1.0),
    spec("nonlinear", Kind::Flag, f32::NAN, false),
    distribution(),
    spec("alpha", Kind::Alpha, super::defaults::ALPHA, false),
];
/// Mitsuba's `principled`, but its index (`eta` or `specular`, one of
/// them: [`principled_eta`]); in the order of [`super::PrincipledRecipe`].
pub const PRINCIPLED: &[Spec] = &[
    reflectance("base_color", 0.5),
    weight("roughness", 0.5),
    weight("anisotropic", 0.0),
    weight("metallic", 0.0),
    weight("spec_trans", 0.0),
    weight("spec_tint", 0.0),
    weight("sheen", 0.0),
    weight("sheen_tint", 0.0),
    weight("flatness", 0.0),
    weight("clearcoat", 0.0),
    weight("clearcoat_gloss", 0.0),
];
/// `principled`'s sampling rates (its diffuse, main specular and
/// clearcoat lobes).
pub const PRINCIPLED_RATES: &[Spec] =
    &[rate("diffuse_reflectance_sampling_rate"), rate("main_specular_sampling_rate"), rate("clearcoat_sampling_rate")];
/// `principled`'s index: a number, or the `specular` it stands for.
pub const PRINCIPLED_ETA: &[Spec] =
    &[spec("eta", Kind::Index, 1.5, false), spec("specular", Kind::Weight(1.0), 0.5, false)];
/// Mitsuba's `principledthin`, in the order of [`super::ThinRecipe`].
pub const PRINCIPLED_THIN: &[Spec] = &[
    reflectance("base_color", 0.5),
    weight("roughness", 0.5),
    weight("anisotropic", 0.0),
    weight("spec_trans", 0.0),
    spec("eta", Kind::Index, 1.5, true),
    weight("spec_tint", 0.0),
    weight("sheen", 0.0),
    weight("sheen_tint", 0.0),
    weight("flatness", 0.0),
    spec("diff_trans", Kind::Weight(2.0), 0.0, true),
];
pub const PRINCIPLED_THIN_RATES: &[Spec] = &[
    rate("specular_reflectance_sampling_rate"),
    rate("specular_transmittance_sampling_rate"),
    rate("diffuse_transmittance_sampling_rate"),
    rate("diffuse_reflectance_sampling_rate"),
];
/// `blendbsdf`: the second material's share, and the two.
pub const BLEND: &[Spec] = &[weight("weight", 0.5), spec("materials", Kind::Materials, f32::NAN, false)];
/// `mask`: the material's opacity (elsewhere nothing is there).
pub const MASK: &[Spec] = &[weight("opacity", 0.5), spec("material", Kind::Material, f32::NAN, false)];
pub const BUMP_MAP: &[Spec] = &[
    spec("texture", Kind::TextureOnly, f32::NAN, true),
    spec("scale", Kind::Signed(1e6), 1.0, false),
    spec("material", Kind::Material, f32::NAN, false),
];
pub const NORMAL_MAP: &[Spec] =
    &[spec("normalmap", Kind::TextureOnly, f32::NAN, true), spec("material", Kind::Material, f32::NAN, false)];
pub const TWO_SIDED: &[Spec] = &[spec("material", Kind::Material, f32::NAN, false)];

const FILTERS: &[&str] = &["bilinear", "nearest"];
const WRAPS: &[&str] = &["repeat", "mirror", "clamp"];

/// Mitsuba's `bitmap` texture (bitmap.cpp): bilinear and repeating by
/// default, an 8-bit image sRGB unless `raw`.
pub const BITMAP: &[Spec] = &[
    spec("filename", Kind::File, f32::NAN, false),
    spec("filter_type", Kind::Choice(FILTERS), f32::NAN, false),
    spec("wrap_mode", Kind::Choice(WRAPS), f32::NAN, false),
    spec("raw", Kind::Flag, f32::NAN, false),
    spec("to_uv", Kind::Transform, f32::NAN, false),
];
/// Mitsuba's `checkerboard` (checkerboard.cpp): colours 0.4 and 0.2.
pub const CHECKERBOARD: &[Spec] = &[
    spec("color0", Kind::Color, 0.4, false),
    spec("color1", Kind::Color, 0.2, false),
    spec("to_uv", Kind::Transform, f32::NAN, false),
];

/// Mitsuba's `mesh_attribute` (mesh_attribute.cpp): a mesh's vertex or
/// face attribute (`vertex_color`, `face_color`, … from a PLY file) times
/// `scale`.
pub const MESH_ATTRIBUTE: &[Spec] =
    &[spec("name", Kind::Name, f32::NAN, false), spec("scale", Kind::Signed(1e30), 1.0, false)];

/// Whether `name` names a mesh attribute (`vertex_…` or `face_…`), else
/// what is wrong.
pub fn attribute_name(name: &str) -> Result<(), String> {
    if name.starts_with("vertex_") || name.starts_with("face_") {
        Ok(())
    } else {
        Err(format!("'{name}' must start with vertex_ or face_"))
    }
}

/// The parameters of material type `kind` (Mitsuba's plugin name), or
/// `None` for a type not defined here.
pub fn of(kind: &str) -> Option<&'static [Spec]> {
    Some(match kind {
        "diffuse" => DIFFUSE,
        "conductor" => CONDUCTOR,
        "roughconductor" => ROUGH_CONDUCTOR,
        "roughdielectric" => ROUGH_DIELECTRIC,
        "thindielectric" => THIN_DIELECTRIC,
        "plastic" => PLASTIC,
        "roughplastic" => ROUGH_PLASTIC,
        "principled" => PRINCIPLED,
        "principledthin" => PRINCIPLED_THIN,
        "blendbsdf" => BLEND,
        "mask" => MASK,
        "bumpmap" => BUMP_MAP,
        "normalmap" => NORMAL_MAP,
        "twosided" => TWO_SIDED,
        _ => return None,
    })
}

/// The spec named `name` in `list`.
pub fn find<'s>(list: &'s [Spec], name: &str) -> Option<&'s Spec> {
    list.iter().find(|s| s.name == name)
}

impl Spec {
    /// The default as a colour.
    pub fn default_color(&self) -> Color {
        Color::splat(self.default)
    }

    /// `c` if it lies in the parameter's range (a number in its first
    /// channel), else what is wrong.
    pub fn check(&self, c: Color) -> Result<Color, String> {
        let ok = match self.kind {
            Kind::Reflectance => c.min_element() >= 0.0 && c.max_element() <= 1.0,
            Kind::Color => c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1e15,
            Kind::Weight(hi) => (0.0..=hi).contains(&c.x),
            Kind::Signed(hi) => (-hi..=hi).contains(&c.x),
            Kind::Alpha => (0.0..=10.0).contains(&c.x),
            Kind::Index => c.x > 0.0 && c.x < 100.0,
            Kind::Rate => c.x > 0.0 && c.x < 1e6,
            _ => true,
        };
        if ok {
            return Ok(c);
        }
        Err(match self.kind {
            Kind::Reflectance => format!("a reflectance must lie in [0, 1], got {c}"),
            Kind::Color => format!("must be finite and not negative, got {c}"),
            Kind::Weight(hi) => format!("must lie in [0, {hi}], got {}", c.x),
            Kind::Signed(hi) => format!("must lie in [-{hi}, {hi}], got {}", c.x),
            Kind::Alpha => format!("must lie in [0, 10], got {}", c.x),
            Kind::Index => format!("must lie in (0, 100), got {}", c.x),
            _ => format!("must be > 0 (and finite), got {}", c.x),
        })
    }
}

/// `principled`'s index from `eta` or `specular` (at most one given), as
/// Mitsuba reads them: with a specular transmission (`spec_trans` given
/// and not 0), an index of 1 becomes 1.001 and a specular of 0 becomes
/// 1e-3, so that the transmission lobe keeps a direction.
pub fn principled_eta(eta: Option<f32>, specular: Option<f32>, has_spec_trans: bool) -> f32 {
    match (eta, specular) {
        (Some(e), _) if has_spec_trans && e == 1.0 => 1.001,
        (Some(e), _) => e,
        (None, s) => {
            let s = s.unwrap_or(0.5);
            super::Principled::eta_of_specular(if has_spec_trans && s == 0.0 { 1e-3 } else { s })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_type_lists_each_name_once_and_its_defaults_lie_in_range() {
        for kind in [
            "diffuse",
            "conductor",
            "roughconductor",
            "roughdielectric",
            "thindielectric",
            "plastic",
            "roughplastic",
            "principled",
            "principledthin",
            "blendbsdf",
            "mask",
            "bumpmap",
            "normalmap",
            "twosided",
        ] {
            let list = of(kind).unwrap();
            for (i, s) in list.iter().enumerate() {
                assert!(list[..i].iter().all(|t| t.name != s.name), "{kind}.{}", s.name);
                if !s.default.is_nan() {
                    assert!(s.check(s.default_color()).is_ok(), "{kind}.{}", s.name);
                }
            }
        }
        let w = find(PRINCIPLED, "roughness").unwrap();
        assert!(w.check(Color::splat(1.5)).is_err() && w.check(Color::splat(0.2)).is_ok());
        assert_eq!(principled_eta(Some(1.0), None, true), 1.001);
        assert_eq!(principled_eta(Some(1.0), None, false), 1.0);
    }
}
