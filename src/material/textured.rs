//! Materials whose parameters vary over a surface: a recipe of fixed
//! values and textures ([`crate::texture`]) that gives the plain
//! [`Material`] at each point a ray or photon meets. Only materials of
//! scenes that use textures are built this way; the rest are plain
//! materials from the start.

use super::disney::Rates;
use super::{Distribution, Material, Principled, PrincipledThin};
use crate::math::Color;
use crate::texture::{SurfacePoint, Texture};

/// A parameter: a fixed value or the value of texture number `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Param {
    Fixed(Color),
    Texture(u32),
}

impl Param {
    #[inline]
    fn color(self, at: &SurfacePoint, textures: &[Texture]) -> Color {
        match self {
            Param::Fixed(c) => c,
            Param::Texture(i) => textures[i as usize].eval(at),
        }
    }

    /// A number: a texture's `eval_1`.
    #[inline]
    pub fn number(self, at: &SurfacePoint, textures: &[Texture]) -> f32 {
        match self {
            Param::Fixed(c) => c.x,
            Param::Texture(i) => textures[i as usize].eval_1(at),
        }
    }

    /// The value averaged over the texture (one half for a texture not
    /// in `textures`: a stand-in while a scene is read).
    pub fn mean(self, textures: &[Texture]) -> Color {
        match self {
            Param::Fixed(c) => c,
            Param::Texture(i) => textures.get(i as usize).map_or(Color::splat(0.5), Texture::mean),
        }
    }

    pub fn is_texture(self) -> bool {
        matches!(self, Param::Texture(_))
    }
}

/// Mitsuba's BSDFs with their texturable parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Textured {
    Diffuse {
        reflectance: Param,
    },
    /// Mitsuba's `mask` over a diffuse BSDF.
    Mask {
        opacity: Param,
        reflectance: Param,
    },
    /// Mitsuba's `blendbsdf` of two diffuse BSDFs: a diffuse BSDF of the
    /// reflectances mixed by `weight` (0 is the first).
    DiffuseBlend {
        weight: Param,
        first: Param,
        second: Param,
    },
    Conductor {
        eta: Color,
        k: Color,
        specular: Param,
    },
    RoughConductor {
        distribution: Distribution,
        alpha_u: Param,
        alpha_v: Param,
        eta: Color,
        k: Color,
        specular: Param,
    },
    RoughDielectric {
        distribution: Distribution,
        alpha_u: Param,
        alpha_v: Param,
        int_ior: f32,
        ext_ior: f32,
        reflectance: Param,
        transmittance: Param,
    },
    Plastic {
        diffuse: Param,
        specular: Param,
        int_ior: f32,
        ext_ior: f32,
        nonlinear: bool,
    },
    RoughPlastic {
        distribution: Distribution,
        alpha: f32,
        diffuse: Param,
        specular: Param,
        int_ior: f32,
        ext_ior: f32,
        nonlinear: bool,
    },
    Principled(PrincipledRecipe),
    PrincipledThin(ThinRecipe),
    /// A blend of two of the scene's materials (their indices), the
    /// second's share `weight` (Mitsuba's `blendbsdf`; its `mask` is a blend
    /// of `null` and the BSDF by the opacity): the scene gives one of them
    /// where a ray or photon meets it ([`super::blend`]).
    Blend {
        weight: Param,
        first: u32,
        second: u32,
    },
}

/// Mitsuba's `principled`: every parameter a texture may give, but the
/// index and the sampling rates.
#[derive(Clone, Debug, PartialEq)]
pub struct PrincipledRecipe {
    pub base_color: Param,
    pub roughness: Param,
    pub anisotropic: Param,
    pub metallic: Param,
    pub spec_trans: Param,
    pub spec_tint: Param,
    pub sheen: Param,
    pub sheen_tint: Param,
    pub flatness: Param,
    pub clearcoat: Param,
    pub clearcoat_gloss: Param,
    pub eta: f32,
    pub rates: Rates,
}

/// Mitsuba's `principledthin`: every parameter a texture may give (its
/// index too), but the sampling rates.
#[derive(Clone, Debug, PartialEq)]
pub struct ThinRecipe {
    pub base_color: Param,
    pub roughness: Param,
    pub anisotropic: Param,
    pub spec_trans: Param,
    pub eta: Param,
    pub spec_tint: Param,
    pub sheen: Param,
    pub sheen_tint: Param,
    pub flatness: Param,
    pub diff_trans: Param,
    pub rates: Rates,
}

impl PrincipledRecipe {
    /// The recipe of the parameters in the order of
    /// [`super::params::PRINCIPLED`].
    pub fn from_params(p: [Param; 11], eta: f32, rates: Rates) -> Self {
        let [base_color, roughness, anisotropic, metallic, spec_trans, spec_tint, sheen, sheen_tint, flatness, clearcoat, clearcoat_gloss] =
            p;
        PrincipledRecipe {
            base_color,
            roughness,
            anisotropic,
            metallic,
            spec_trans,
            spec_tint,
            sheen,
            sheen_tint,
            flatness,
            clearcoat,
            clearcoat_gloss,
            eta,
            rates,
        }
    }

    pub fn params(&self) -> [Param; 11] {
        [
            self.base_color,
            self.roughness,
            self.anisotropic,
            self.metallic,
            self.spec_trans,
            self.spec_tint,
            self.sheen,
            self.sheen_tint,
            self.flatness,
            self.clearcoat,
            self.clearcoat_gloss,
        ]
    }
}

impl ThinRecipe {
    /// The recipe of the parameters in the order of
    /// [`super::params::PRINCIPLED_THIN`].
    pub fn from_params(p: [Param; 10], rates: Rates) -> Self {
        let [base_color, roughness, anisotropic, spec_trans, eta, spec_tint, sheen, sheen_tint, flatness, diff_trans] =
            p;
        ThinRecipe {
            base_color,
            roughness,
            anisotropic,
            spec_trans,
            eta,
            spec_tint,
            sheen,
            sheen_tint,
            flatness,
            diff_trans,
            rates,
        }
    }

    pub fn params(&self) -> [Param; 10] {
        [
            self.base_color,
            self.roughness,
            self.anisotropic,
            self.spec_trans,
            self.eta,
            self.spec_tint,
            self.sheen,
            self.sheen_tint,
            self.flatness,
            self.diff_trans,
        ]
    }
}

impl Textured {
    /// Whether any parameter is a texture (else the material is plain).
    pub fn reads_textures(&self) -> bool {
        let params: &[Param] = match self {
            Textured::Diffuse { reflectance } => &[*reflectance],
            Textured::Mask { opacity, reflectance } => &[*opacity, *reflectance],
            Textured::DiffuseBlend { weight, first, second } => &[*weight, *first, *second],
            Textured::Conductor { specular, .. } => &[*specular],
            Textured::RoughConductor { alpha_u, alpha_v, specular, .. } => &[*alpha_u, *alpha_v, *specular],
            Textured::RoughDielectric { alpha_u, alpha_v, reflectance, transmittance, .. } => {
                &[*alpha_u, *alpha_v, *reflectance, *transmittance]
            }
            Textured::Plastic { diffuse, specular, .. } | Textured::RoughPlastic { diffuse, specular, .. } => {
                &[*diffuse, *specular]
            }
            Textured::Principled(r) => return r.params().iter().any(|p| p.is_texture()),
            // Resolved where it is met, whether its weight is a texture or not.
            Textured::Blend { .. } => return true,
            Textured::PrincipledThin(r) => return r.params().iter().any(|p| p.is_texture()),
        };
        params.iter().any(|p| p.is_texture())
    }

    /// The material at `at`. Reflectances are kept within [0, 1] and
    /// roughness within Mitsuba's range, whatever an image holds.
    pub fn at(&self, at: &SurfacePoint, textures: &[Texture]) -> Material {
        self.build(|p| p.color(at, textures), |p| p.number(at, textures))
    }

    /// The material with every texture at its mean: what the renderer
    /// asks of a material as a whole (which lobes it has).
    pub fn typical(&self, textures: &[Texture]) -> Material {
        self.build(|p| p.mean(textures), |p| p.mean(textures).x)
    }

    fn build(&self, color: impl Fn(Param) -> Color, number: impl Fn(Param) -> f32) -> Material {
        let unit = |p: Param| color(p).clamp(Color::ZERO, Color::ONE);
        let alpha = |p: Param| number(p).clamp(0.0, 10.0);
        // Mitsuba documents the principled BSDFs' weights on [0, 1] (the
        // diffuse transmission on [0, 2]); an image outside is held there.
        let weight = |p: Param| number(p).clamp(0.0, 1.0);
        match *self {
            Textured::Diffuse { reflectance } => Material::Lambertian { rho: unit(reflectance) },
            Textured::Mask { opacity, reflectance } => {
                Material::Masked(super::Masked { opacity: number(opacity).clamp(0.0, 1.0), rho: unit(reflectance) })
            }
            Textured::DiffuseBlend { weight, first, second } => {
                let w = number(weight).clamp(0.0, 1.0);
                Material::Lambertian { rho: unit(first) * (1.0 - w) + unit(second) * w }
            }
            Textured::Conductor { eta, k, specular } => Material::conductor(eta, k, unit(specular)),
            Textured::RoughConductor { distribution, alpha_u, alpha_v, eta, k, specular } => {
                Material::rough_conductor(distribution, alpha(alpha_u), alpha(alpha_v), eta, k, unit(specular))
            }
            Textured::RoughDielectric {
                distribution,
                alpha_u,
                alpha_v,
                int_ior,
                ext_ior,
                reflectance,
                transmittance,
            } => Material::rough_dielectric(
                distribution,
                alpha(alpha_u),
                alpha(alpha_v),
                int_ior,
                ext_ior,
                unit(reflectance),
                unit(transmittance),
            ),
            Textured::Plastic { diffuse, specular, int_ior, ext_ior, nonlinear } => {
                Material::plastic(unit(diffuse), unit(specular), int_ior, ext_ior, nonlinear)
            }
            Textured::RoughPlastic { distribution, alpha, diffuse, specular, int_ior, ext_ior, nonlinear } => {
                Material::rough_plastic(distribution, alpha, unit(diffuse), unit(specular), int_ior, ext_ior, nonlinear)
            }
            Textured::Principled(ref r) => Material::Principled(Principled {
                base_color: unit(r.base_color),
                roughness: weight(r.roughness),
                anisotropic: weight(r.anisotropic),
                metallic: weight(r.metallic),
                spec_trans: weight(r.spec_trans),
                eta: r.eta,
                spec_tint: weight(r.spec_tint),
                sheen: weight(r.sheen),
                sheen_tint: weight(r.sheen_tint),
                flatness: weight(r.flatness),
                clearcoat: weight(r.clearcoat),
                clearcoat_gloss: weight(r.clearcoat_gloss),
                rates: r.rates,
                back: false,
            }),
            // The scene summarises the blend from its materials.
            Textured::Blend { .. } => Material::Blend(super::Blend::default()),
            Textured::PrincipledThin(ref r) => Material::PrincipledThin(PrincipledThin {
                base_color: unit(r.base_color),
                roughness: weight(r.roughness),
                anisotropic: weight(r.anisotropic),
                spec_trans: weight(r.spec_trans),
                eta: number(r.eta).clamp(1e-3, 100.0),
                spec_tint: weight(r.spec_tint),
                sheen: weight(r.sheen),
                sheen_tint: weight(r.sheen_tint),
                flatness: weight(r.flatness),
                diff_trans: number(r.diff_trans).clamp(0.0, 2.0),
                rates: r.rates,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Affine2, Vec2};

    #[test]
    fn a_textured_diffuse_takes_the_texture_where_it_is_read() {
        let textures = [Texture::Checkerboard {
            color0: Color::splat(0.8),
            color1: Color::new(0.1, 0.2, 0.3),
            to_uv: Affine2::IDENTITY,
        }];
        let t = Textured::Diffuse { reflectance: Param::Texture(0) };
        let at = |u: f32| SurfacePoint { uv: Vec2::new(u, 0.25), prim: 0, bary: Vec2::ZERO };
        assert_eq!(t.at(&at(0.25), &textures), Material::Lambertian { rho: Color::splat(0.8) });
        assert_eq!(t.at(&at(0.75), &textures), Material::Lambertian { rho: Color::new(0.1, 0.2, 0.3) });
        let mean = t.typical(&textures).diffuse_rho().unwrap();
        assert!((mean - Color::new(0.45, 0.5, 0.55)).length() < 1e-6);
        let blend = Textured::DiffuseBlend {
            weight: Param::Fixed(Color::splat(0.25)),
            first: Param::Fixed(Color::ONE),
            second: Param::Texture(0),
        };
        let rho = blend.at(&at(0.25), &textures).diffuse_rho().unwrap();
        assert!((rho - Color::splat(0.75 + 0.25 * 0.8)).length() < 1e-6);
    }
}
