//! Surface materials: a closed set, each answering for itself in the local
//! frame of the surface (TNCG15's local coordinate systems): the normal is
//! +z on the side the ray or photon arrives from, `wo` points back along
//! it (so `wo.z > 0`), and `entering` says whether that side is the front
//! of the geometric normal (for glass: whether light enters the body).
//!
//! A material has up to three kinds of lobe, each owned by one estimator of
//! photon mapping (notes/method.md):
//! * **diffuse** (Lambertian, a plastic's base): where photons are stored
//!   and density estimates read ([`Material::diffuse_rho`],
//!   [`Material::diffuse_albedo`]);
//! * **glossy** (Phong's lobe, rough metal and glass, a rough plastic's
//!   coat): sampled like a path tracer ([`Material::glossy`], [`Glossy`]);
//! * **specular** (mirror, glass, smooth metal, thin glass, Phong's mirror,
//!   a smooth plastic's coat): perfect reflection and refraction, followed
//!   by rays ([`Material::specular_branches`]).
//!
//! [`Material::eval`] and [`Material::pdf`] cover the smooth lobes (diffuse
//! and glossy); [`Material::sample`] picks any lobe. Adding a material is a
//! variant here and its answers to these questions, and its fields in the
//! scene file (notes/architecture.md).
//!
//! Mitsuba 3's BSDFs map onto constructors with its parameter names and
//! meanings (colours as RGB, named materials and indices converted by the
//! front-end):
//!
//! | Mitsuba | constructor |
//! |---|---|
//! | `conductor` | [`Material::conductor`]`(eta, k, specular_reflectance)` |
//! | `roughconductor` | [`Material::rough_conductor`]`(distribution, alpha_u, alpha_v, eta, k, specular_reflectance)` |
//! | `roughdielectric` | [`Material::rough_dielectric`]`(distribution, alpha_u, alpha_v, int_ior, ext_ior, specular_reflectance, specular_transmittance)` |
//! | `thindielectric` | [`Material::thin_dielectric`]`(int_ior, ext_ior, specular_reflectance, specular_transmittance)` |
//! | `plastic` | [`Material::plastic`]`(diffuse_reflectance, specular_reflectance, int_ior, ext_ior, nonlinear)` |
//! | `roughplastic` | [`Material::rough_plastic`]`(distribution, alpha, diffuse_reflectance, specular_reflectance, int_ior, ext_ior, nonlinear)` |
//! | `principled` | [`Material::Principled`]`(`[`Principled`]`)` |
//! | `principledthin` | [`Material::PrincipledThin`]`(`[`PrincipledThin`]`)` |
//!
//! Isotropic roughness is `alpha_u = alpha_v = alpha`; anisotropic alpha_u
//! runs along the first tangent of the shading frame (`math::Frame`, built
//! from the normal: meshes carry no texture-space tangents yet). Mitsuba's
//! defaults are in [`defaults`].

mod blend;
mod conductor;
pub mod conductors;
mod dielectric;
pub mod disney;
mod glossy;
pub mod indices;
mod mask;
pub mod microfacet;
mod mitsuba;
pub mod params;
mod phong;
mod plastic;
mod principled;
mod principled_thin;
mod textured;

pub use blend::{hit_random, Blend, Mix};
pub use conductor::{Conductor, RoughConductor};
pub use dielectric::{RoughDielectric, ThinDielectric};
pub use glossy::{Glossy, CAUSTIC_ROUGHNESS};
pub use mask::Masked;
pub use microfacet::{Distribution, Microfacet};
pub use phong::Phong;
pub use plastic::{fresnel_diffuse_reflectance, Plastic, RoughPlastic};
pub use principled::Principled;
pub use principled_thin::PrincipledThin;
pub use textured::{Param, PrincipledRecipe, Textured, ThinRecipe};

use crate::math::{max_component, Color};
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf, next_2d, Rng};
use glam::Vec3;
use rand::RngExt;
use std::f32::consts::PI;

/// Mitsuba 3's defaults for the parameters of its BSDFs.
pub mod defaults {
    use super::microfacet::Distribution;
    /// `distribution` of roughconductor, roughdielectric, roughplastic.
    pub const DISTRIBUTION: Distribution = Distribution::Beckmann;
    /// `alpha` of the rough BSDFs.
    pub const ALPHA: f32 = 0.1;
    /// `int_ior` of the dielectrics ("bk7") and of the plastics ("polypropylene").
    pub const DIELECTRIC_INT_IOR: f32 = super::indices::BK7;
    pub const PLASTIC_INT_IOR: f32 = super::indices::POLYPROPYLENE;
    /// `ext_ior` ("air").
    pub const EXT_IOR: f32 = super::indices::AIR;
    /// A conductor's `eta` and `k` with no named material: a perfect mirror.
    pub const CONDUCTOR_ETA: f32 = 0.0;
    pub const CONDUCTOR_K: f32 = 1.0;
    /// A plastic's `diffuse_reflectance`.
    pub const DIFFUSE_REFLECTANCE: f32 = 0.5;
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Ideal diffuse reflector, BRDF = rho / pi, per channel.
    Lambertian { rho: Color },
    /// Perfect specular mirror.
    Mirror { reflectance: Color },
    /// Smooth dielectric: exact Fresnel, Snell refraction, total internal
    /// reflection. `ior` is the index inside (the side the normal points
    /// away from); light travelling inside loses exp(-absorption * distance)
    /// per channel (Beer–Lambert).
    Glass { ior: f32, absorption: Color },
    /// The Whitted course's material (see [`Phong`]).
    Phong(Phong),
    /// Smooth metal: a mirror of Fresnel's complex-index reflectance.
    Conductor(Conductor),
    /// Rough metal: a microfacet lobe.
    RoughConductor(RoughConductor),
    /// Rough glass: microfacet reflection and transmission.
    RoughDielectric(RoughDielectric),
    /// A thin pane: reflection and straight transmission.
    ThinDielectric(ThinDielectric),
    /// A diffuse base under a smooth dielectric coat.
    Plastic(Plastic),
    /// A diffuse base under a rough dielectric coat.
    RoughPlastic(RoughPlastic),
    /// A diffuse surface cut out by an opacity ([`Masked`]).
    Masked(Masked),
    /// Mitsuba's principled BSDF (Burley's Disney BSDF); one-sided: its
    /// back ([`Material::back_side`]) keeps the specular lobes alone.
    Principled(Principled),
    /// Mitsuba's thin principled BSDF: a sheet, the same from both sides.
    PrincipledThin(PrincipledThin),
    /// A blend of two of the scene's materials, as the scene sees it as a
    /// whole ([`Blend`]); where a ray or photon meets it, the scene gives
    /// one of the two.
    Blend(Blend),
    /// A light's own surface: it emits (through its light) and reflects nothing.
    Emitter,
}

/// Which way a path carries light, where it matters: a camera path
/// (radiance) crossing into glass is scaled by (n_i / n_t)^2, a photon
/// (importance, carrying power) is not (Veach 1997, ch. 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    Radiance,
    Importance,
}

/// The kind of lobe a scattered direction came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    Diffuse,
    Glossy,
    Specular,
}

/// A direction a material scattered into.
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    /// Local, unit length (to rounding; specular directions are mapped to
    /// world space and normalised by the caller, see [`Lobe`]).
    pub wi: Vec3,
    /// What the path's weight is multiplied by: f |cos| / pdf, the chance
    /// of the lobe's choice included; for a specular branch its scale.
    pub weight: Color,
    pub lobe: Lobe,
}

/// One perfect reflection or refraction leaving a surface.
#[derive(Clone, Copy, Debug)]
pub struct Branch {
    /// Local direction (unit to rounding).
    pub wi: Vec3,
    /// The share of the light this branch takes (Fresnel's for glass, 1 for
    /// a mirror), and the chance it is chosen when only one is followed.
    pub prob: f32,
    /// What light along the branch is multiplied by besides `prob`: a
    /// mirror's reflectance, refraction's radiance scale.
    pub scale: Color,
}

/// A material's specular branches: none, one (a mirror, total internal
/// reflection), or two (glass: reflection and refraction).
#[derive(Clone, Copy, Debug, Default)]
pub struct Branches {
    items: [Option<Branch>; 2],
}

impl Branches {
    fn one(b: Branch) -> Self {
        Branches { items: [Some(b), None] }
    }

    pub fn iter(&self) -> impl Iterator<Item = &Branch> {
        self.items.iter().flatten()
    }

    pub fn is_empty(&self) -> bool {
        self.items[0].is_none()
    }

    /// One branch chosen with its probability; a lone branch is taken
    /// without drawing (a mirror costs no random number).
    pub fn choose(&self, rng: &mut Rng) -> Option<Branch> {
        match self.items {
            [Some(a), Some(b)] => Some(if rng.random::<f32>() < a.prob { a } else { b }),
            [a, _] => a,
        }
    }
}

impl Material {
    /// Clear glass of index `ior`.
    pub fn glass(ior: f32) -> Self {
        Material::Glass { ior, absorption: Color::ZERO }
    }

    /// Mitsuba's `conductor`: complex index `eta` + i `k` per channel,
    /// times `specular` (its specular_reflectance).
    pub fn conductor(eta: Color, k: Color, specular: Color) -> Self {
        Material::Conductor(Conductor { eta, k, specular })
    }

    /// Mitsuba's `roughconductor` (alpha below 1e-4 is raised to it).
    pub fn rough_conductor(
        distribution: Distribution,
        alpha_u: f32,
        alpha_v: f32,
        eta: Color,
        k: Color,
        specular: Color,
    ) -> Self {
        let microfacet = Microfacet::new(distribution, alpha_u, alpha_v);
        Material::RoughConductor(RoughConductor { microfacet, eta, k, specular })
    }

    /// Mitsuba's `roughdielectric`: `int_ior` inside (the side the
    /// geometric normal points away from), `ext_ior` outside; they must
    /// differ and be positive (the scene readers check).
    pub fn rough_dielectric(
        distribution: Distribution,
        alpha_u: f32,
        alpha_v: f32,
        int_ior: f32,
        ext_ior: f32,
        specular_reflectance: Color,
        specular_transmittance: Color,
    ) -> Self {
        let microfacet = Microfacet::new(distribution, alpha_u, alpha_v);
        Material::RoughDielectric(RoughDielectric {
            microfacet,
            int_ior,
            ext_ior,
            specular_reflectance,
            specular_transmittance,
        })
    }

    /// Mitsuba's `thindielectric`.
    pub fn thin_dielectric(
        int_ior: f32,
        ext_ior: f32,
        specular_reflectance: Color,
        specular_transmittance: Color,
    ) -> Self {
        Material::ThinDielectric(ThinDielectric { int_ior, ext_ior, specular_reflectance, specular_transmittance })
    }

    /// Mitsuba's `plastic`.
    pub fn plastic(diffuse: Color, specular: Color, int_ior: f32, ext_ior: f32, nonlinear: bool) -> Self {
        Material::Plastic(Plastic { diffuse, specular, eta: int_ior / ext_ior, nonlinear })
    }

    /// Mitsuba's `roughplastic` (isotropic, as Mitsuba's). The coat's
    /// tables are computed on the first use of a (distribution, alpha,
    /// index) and shared.
    #[allow(clippy::too_many_arguments)]
    pub fn rough_plastic(
        distribution: Distribution,
        alpha: f32,
        diffuse: Color,
        specular: Color,
        int_ior: f32,
        ext_ior: f32,
        nonlinear: bool,
    ) -> Self {
        let microfacet = Microfacet::isotropic(distribution, alpha);
        Material::RoughPlastic(RoughPlastic::new(microfacet, diffuse, specular, int_ior / ext_ior, nonlinear))
    }

    /// What a one-sided material is seen as from behind: black, but for
    /// a mask, which still lets light through.
    pub fn back_side(&self) -> Material {
        match *self {
            Material::Masked(m) => Material::Masked(Masked { rho: Color::ZERO, ..m }),
            Material::Principled(p) => Material::Principled(Principled { back: true, ..p }),
            _ => Material::Lambertian { rho: Color::ZERO },
        }
    }

    pub fn is_emitter(&self) -> bool {
        matches!(self, Material::Emitter)
    }

    /// Mirror, glass, smooth metal and thin glass: all light leaving them
    /// is found by following rays, never by density estimation.
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. } | Material::Glass { .. } | Material::Conductor(_) | Material::ThinDielectric(_)
        )
    }

    /// Whether light can leave the surface by a perfect mirror or
    /// refraction, or a glossy lobe that carries caustics (photons aimed
    /// at it may make caustics).
    pub fn has_specular_lobe(&self) -> bool {
        match self {
            Material::Phong(p) => max_component(p.mirror_rho()) > 0.0,
            Material::Plastic(p) => max_component(p.specular) > 0.0,
            Material::Masked(m) => m.through() > 0.0,
            Material::Blend(b) => b.specular,
            Material::RoughConductor(_)
            | Material::RoughDielectric(_)
            | Material::RoughPlastic(_)
            | Material::Principled(_)
            | Material::PrincipledThin(_) => self.glossy().is_some_and(|g| g.carries_caustics()),
            m => m.is_specular(),
        }
    }

    /// The diffuse lobe's reflectance: where photons are stored and density
    /// estimates read. `None` where there is none, or it is black (a black
    /// surface reflects nothing and needs no estimate). For a plastic, its
    /// base's reflectance; what it reflects towards a direction is
    /// [`Self::diffuse_albedo`].
    pub fn diffuse_rho(&self) -> Option<Color> {
        let rho = match self {
            Material::Lambertian { rho } => *rho,
            Material::Phong(p) => p.diffuse_rho(),
            Material::Plastic(p) => p.diffuse,
            Material::RoughPlastic(p) => p.diffuse,
            Material::Masked(m) => m.rho(),
            Material::Blend(b) => return b.diffuse,
            Material::Principled(p) => return p.diffuse_rho(),
            Material::PrincipledThin(p) => return p.diffuse_rho(),
            _ => return None,
        };
        (max_component(rho) > 0.0).then_some(rho)
    }

    /// What the diffuse lobe reflects towards `wo` of light arriving evenly
    /// from above (pi times its BRDF where that is constant): the factor a
    /// density estimate of irradiance takes. Exact for Lambertian and
    /// Phong; a plastic's depends on where the light arrives from through
    /// its coat's Fresnel, which an irradiance estimate does not know (its
    /// direct light, by shadow rays, is exact).
    #[inline]
    pub fn diffuse_albedo(&self, wo: Vec3) -> Color {
        match self {
            Material::Lambertian { rho } => *rho,
            Material::Phong(p) => p.diffuse_rho(),
            Material::Plastic(_)
            | Material::RoughPlastic(_)
            | Material::Principled(_)
            | Material::PrincipledThin(_) => self.mitsuba_diffuse_albedo(wo),
            Material::Masked(m) => m.rho(),
            _ => Color::ZERO,
        }
    }

    /// The glossy lobe, if the material has one that reflects.
    #[inline]
    pub fn glossy(&self) -> Option<Glossy<'_>> {
        match self {
            Material::Phong(p) if p.is_glossy() => Some(Glossy::Phong(p)),
            Material::RoughConductor(c) => Some(Glossy::Conductor(c)),
            Material::RoughDielectric(d) => Some(Glossy::Dielectric(d)),
            Material::RoughPlastic(p) if max_component(p.specular) > 0.0 => Some(Glossy::Coat(p)),
            Material::Principled(p) if p.has_glossy() => Some(Glossy::Principled(p)),
            Material::PrincipledThin(p) if p.has_glossy() => Some(Glossy::Thin(p)),
            _ => None,
        }
    }

    /// Whether the smooth lobes let light through (their direct light is
    /// sought on both sides).
    #[inline]
    pub fn transmits(&self) -> bool {
        match self {
            Material::RoughDielectric(_) => true,
            Material::Principled(p) => p.transmits(),
            Material::PrincipledThin(p) => p.transmits(),
            _ => false,
        }
    }

    /// Whether the material has a diffuse or glossy lobe (light arriving
    /// there is estimated, not only followed).
    #[inline]
    pub fn has_smooth_lobes(&self) -> bool {
        self.diffuse_rho().is_some() || self.glossy().is_some()
    }

    /// What light travelling inside loses per unit length (Beer–Lambert),
    /// where that is anything.
    pub fn absorption(&self) -> Option<Color> {
        match *self {
            Material::Glass { absorption, .. } if absorption != Color::ZERO => Some(absorption),
            _ => None,
        }
    }

    /// The chance a photon arriving from `wo` goes on from this surface
    /// (Russian roulette): the largest fraction of power the smooth lobes
    /// and Phong's mirror reflect (Jensen 2001, ch. 5), a plastic's towards
    /// `wo`; 1 for mirrors, glass and metals, whose photons are never
    /// dropped (their chains make the caustics).
    pub fn photon_survival(&self, wo: Vec3) -> f32 {
        match self {
            Material::Lambertian { rho } => max_component(*rho).min(1.0),
            Material::Phong(p) => p.lobe_weights().iter().sum::<f32>().min(1.0),
            Material::Mirror { .. } | Material::Glass { .. } => 1.0,
            Material::Emitter => 0.0,
            _ => self.mitsuba_photon_survival(wo),
        }
    }

    /// How the Whitted course's formula reads the material (the `trace`
    /// program): Phong as itself, a Lambertian rho as C = rho, m_l = 1 / pi,
    /// m_a = 1 (its direct light is then photonmap's); `None` where only
    /// its specular branches (mirrors, glass) or nothing (lights) reflect.
    pub fn course_phong(&self) -> Option<Phong> {
        match *self {
            Material::Phong(p) => Some(p),
            Material::Lambertian { rho } => Some(Phong {
                color: rho,
                ambient: 1.0,
                diffuse: 1.0 / PI,
                specular: 0.0,
                metalness: 0.0,
                shininess: 1.0,
                mirror: 0.0,
            }),
            _ => None,
        }
    }

    /// The smooth part of the BSDF, f(wo, wi), for local directions: on the
    /// surface's side, and for rough glass also through it (`wi.z < 0`;
    /// zero elsewhere); specular lobes are not included. `mode` matters
    /// only across a boundary (radiance's 1 / eta^2).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, entering: bool, mode: Transport) -> Color {
        match self {
            Material::Lambertian { rho } if wi.z > 0.0 => *rho / PI,
            Material::Phong(p) if wi.z > 0.0 => p.diffuse_rho() / PI + p.glossy(wo, wi),
            Material::Lambertian { .. } | Material::Phong(_) | Material::Mirror { .. } | Material::Glass { .. } => {
                Color::ZERO
            }
            Material::Emitter => Color::ZERO,
            _ => self.mitsuba_eval(wo, wi, entering, mode),
        }
    }

    /// The density (per solid angle) with which [`Self::sample`] returns
    /// `wi` through a smooth lobe.
    pub fn pdf(&self, wo: Vec3, wi: Vec3, entering: bool) -> f32 {
        match self {
            Material::Lambertian { .. } => cosine_hemisphere_pdf(wi),
            Material::Phong(p) => {
                let [d, g, m] = p.lobe_weights();
                let total = d + g + m;
                if !(total > 0.0) {
                    return 0.0;
                }
                (d * cosine_hemisphere_pdf(wi) + g * p.glossy_pdf(wo, wi)) / total
            }
            Material::Mirror { .. } | Material::Glass { .. } | Material::Emitter => 0.0,
            _ => self.mitsuba_pdf(wo, wi, entering),
        }
    }

    /// The perfect reflections and refractions leaving the surface towards
    /// `wo`'s side or through it. Glass: reflection with Fresnel's share
    /// and refraction with the rest (scaled by (n_i / n_t)^2 for radiance),
    /// or reflection alone past the critical angle. A thin pane: its
    /// reflectance's share, and straight through with the rest (no change
    /// of medium, no scale).
    #[inline]
    pub fn specular_branches(&self, wo: Vec3, entering: bool, mode: Transport) -> Branches {
        match *self {
            Material::Mirror { reflectance } if max_component(reflectance) > 0.0 => {
                Branches::one(Branch { wi: reflect(wo), prob: 1.0, scale: reflectance })
            }
            Material::Phong(p) if max_component(p.mirror_rho()) > 0.0 => {
                Branches::one(Branch { wi: reflect(wo), prob: 1.0, scale: p.mirror_rho() })
            }
            Material::Glass { ior, .. } => {
                let (n_i, n_t) = if entering { (1.0, ior) } else { (ior, 1.0) };
                let reflected = |prob| Branch { wi: reflect(wo), prob, scale: Color::ONE };
                match refract(wo, n_i / n_t) {
                    None => Branches::one(reflected(1.0)),
                    Some(wt) => {
                        let r = fresnel_dielectric(wo.z, n_i, n_t);
                        let scale = match mode {
                            Transport::Radiance => Color::splat((n_i / n_t).powi(2)),
                            Transport::Importance => Color::ONE,
                        };
                        Branches { items: [Some(reflected(r)), Some(Branch { wi: wt, prob: 1.0 - r, scale })] }
                    }
                }
            }
            Material::Conductor(_) | Material::ThinDielectric(_) | Material::Plastic(_) | Material::Masked(_) => {
                self.mitsuba_specular_branches(wo)
            }
            _ => Branches::default(),
        }
    }

    /// A scattered direction from one of the material's lobes, chosen in
    /// proportion to what each reflects (Phong: the largest channel of each
    /// lobe's albedo; glass: Fresnel's shares). The weight is f |cos| /
    /// pdf over the smooth lobes ([`Self::eval`], [`Self::pdf`]), or a
    /// specular branch's scale over the chance of its lobe. `None` for a
    /// surface that reflects nothing, or a glossy sample below the surface.
    pub fn sample(&self, wo: Vec3, entering: bool, mode: Transport, rng: &mut Rng) -> Option<Scatter> {
        let specular = |b: Branch| Scatter { wi: b.wi, weight: b.scale, lobe: Lobe::Specular };
        match self {
            Material::Lambertian { rho } => {
                // Cosine sampling: f cos / pdf = (rho / pi) cos / (cos / pi) = rho.
                Some(Scatter { wi: cosine_hemisphere(next_2d(rng)), weight: *rho, lobe: Lobe::Diffuse })
            }
            Material::Mirror { .. } | Material::Glass { .. } => {
                self.specular_branches(wo, entering, mode).choose(rng).map(specular)
            }
            Material::Phong(p) => {
                let w = p.lobe_weights();
                let total: f32 = w.iter().sum();
                if !(total > 0.0) {
                    return None;
                }
                let u = rng.random::<f32>() * total;
                if u < w[0] + w[1] {
                    // A smooth lobe's direction is weighed by the smooth
                    // lobes' mixture (f cos / pdf with the pdf of both), so
                    // that neither lobe's samples miss the other's light.
                    let (wi, lobe) = if u < w[0] {
                        (cosine_hemisphere(next_2d(rng)), Lobe::Diffuse)
                    } else {
                        (p.sample_glossy(wo, next_2d(rng))?.0, Lobe::Glossy)
                    };
                    let pdf = self.pdf(wo, wi, entering);
                    (pdf > 0.0).then(|| Scatter { wi, weight: self.eval(wo, wi, entering, mode) * (wi.z / pdf), lobe })
                } else {
                    let b = self.specular_branches(wo, entering, mode).choose(rng)?;
                    Some(Scatter { weight: b.scale * (total / w[2]), ..specular(b) })
                }
            }
            Material::Emitter => None,
            _ => self.mitsuba_sample(wo, entering, mode, rng),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{stream, uniform_cone, Domain};

    fn phong() -> Phong {
        Phong {
            color: Color::new(0.9, 0.6, 0.3),
            ambient: 0.0,
            diffuse: 0.4,
            specular: 0.3,
            metalness: 0.2,
            shininess: 20.0,
            mirror: 0.2,
        }
    }

    fn materials() -> Vec<Material> {
        vec![
            Material::Lambertian { rho: Color::new(0.8, 0.5, 0.2) },
            Material::Mirror { reflectance: Color::splat(0.95) },
            Material::glass(1.5),
            Material::Phong(phong()),
        ]
    }

    /// For every material, the mean weight of its samples is the fraction
    /// of light it reflects towards `wo` (a white furnace per direction):
    /// the smooth lobes' integral of f cos, estimated independently with
    /// uniform directions, plus the specular branches' shares.
    #[test]
    fn sample_weights_average_to_the_reflected_fraction() {
        let mut rng = stream(2, Domain::Camera, 0);
        for m in materials() {
            for wo in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.95, 0.3122499).normalize()] {
                let n = 400_000;
                let mut sampled = Color::ZERO.as_dvec3();
                for _ in 0..n {
                    if let Some(s) = m.sample(wo, true, Transport::Importance, &mut rng) {
                        sampled += s.weight.as_dvec3();
                    }
                }
                let mut smooth = Color::ZERO.as_dvec3();
                for _ in 0..n {
                    let wi = uniform_cone(next_2d(&mut rng), 0.0);
                    smooth += (m.eval(wo, wi, true, Transport::Importance) * wi.z * 2.0 * PI).as_dvec3();
                }
                let specular: Color =
                    m.specular_branches(wo, true, Transport::Importance).iter().map(|b| b.prob * b.scale).sum();
                let want = smooth / n as f64 + specular.as_dvec3();
                let got = sampled / n as f64;
                for c in 0..3 {
                    assert!((got[c] - want[c]).abs() < 0.01 + 0.01 * want[c], "{m:?} wo {wo}: {got} vs {want}");
                }
            }
        }
    }

    /// Where a sample came from a smooth lobe, its weight is f cos / pdf
    /// by the material's own eval and pdf (sampler and pdf agree).
    #[test]
    fn smooth_samples_weigh_f_cos_over_pdf() {
        let mut rng = stream(3, Domain::Camera, 0);
        let wo = Vec3::new(0.3, 0.4, 0.866).normalize();
        for m in [Material::Lambertian { rho: Color::splat(0.7) }, Material::Phong(Phong { mirror: 0.0, ..phong() })] {
            let mut checked = 0;
            for _ in 0..20_000 {
                let Some(s) = m.sample(wo, true, Transport::Radiance, &mut rng) else { continue };
                if s.lobe == Lobe::Specular {
                    continue;
                }
                let want = m.eval(wo, s.wi, true, Transport::Radiance) * s.wi.z / m.pdf(wo, s.wi, true);
                assert!((s.weight - want).abs().max_element() <= 1e-3 * want.max_element(), "{s:?} vs {want}");
                checked += 1;
            }
            assert!(checked > 10_000);
        }
    }

    /// Glass: the shares add to one, refraction follows Snell, a camera
    /// path crossing in is scaled by (1 / 1.5)^2 and a photon is not; past
    /// the critical angle from inside, reflection alone.
    #[test]
    fn glass_branches_share_the_light() {
        let glass = Material::glass(1.5);
        let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        let b: Vec<Branch> = glass.specular_branches(wo, true, Transport::Radiance).iter().copied().collect();
        assert_eq!(b.len(), 2);
        assert!((b[0].prob + b[1].prob - 1.0).abs() < 1e-6);
        assert!(b[1].wi.z < 0.0 && (0.5 - 1.5 * b[1].wi.x.abs()).abs() < 1e-6);
        assert!((b[1].scale.x - 1.0 / 2.25).abs() < 1e-6);
        let photon: Vec<Branch> = glass.specular_branches(wo, true, Transport::Importance).iter().copied().collect();
        assert_eq!(photon[1].scale, Color::ONE);
        let grazing = Vec3::new(0.9, 0.0, 0.19f32.sqrt());
        let inside: Vec<Branch> =
            glass.specular_branches(grazing, false, Transport::Radiance).iter().copied().collect();
        assert_eq!(inside.len(), 1);
        assert_eq!(inside[0].prob, 1.0);
    }

    /// Materials are copied freely and indexed per hit: the largest
    /// variant (a rough plastic, its coat's tables shared by reference)
    /// keeps the enum at 64 bytes.
    #[test]
    fn a_material_stays_small() {
        assert!(std::mem::size_of::<Material>() <= 64, "{} bytes", std::mem::size_of::<Material>());
    }

    #[test]
    fn what_photon_mapping_asks_of_each_material() {
        let [lambert, mirror, glass, phong] = materials().try_into().unwrap();
        assert_eq!(lambert.diffuse_rho(), Some(Color::new(0.8, 0.5, 0.2)));
        assert!((lambert.photon_survival(Vec3::Z) - 0.8).abs() < 1e-6);
        assert!(mirror.diffuse_rho().is_none() && mirror.is_specular() && mirror.photon_survival(Vec3::Z) == 1.0);
        assert!(glass.has_specular_lobe() && glass.absorption().is_none());
        assert!(phong.has_specular_lobe() && phong.glossy().is_some() && phong.diffuse_rho().is_some());
        assert!(Material::Lambertian { rho: Color::ZERO }.diffuse_rho().is_none());
        assert!(Material::Emitter
            .sample(Vec3::Z, true, Transport::Radiance, &mut stream(1, Domain::Camera, 0))
            .is_none());
    }
}
