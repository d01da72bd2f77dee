//! The answers of the materials with Mitsuba 3's parameters (metals, rough
//! and thin glass, plastics) to `Material`'s questions. They are kept out
//! of the functions the course's materials answer in, which the photon pass
//! and the camera pass call at every hit: those stay small enough to be
//! inlined, and a scene without the new materials runs the code it ran
//! before (notes/performance.md).

use super::{Branch, Branches, Lobe, Material, Scatter, Transport};
use crate::math::{max_component, Color};
use crate::optics::reflect;
use crate::sampling::{cosine_hemisphere, next_2d, Rng};
use glam::Vec3;
use rand::RngExt;

impl Material {
    #[inline(never)]
    pub(super) fn mitsuba_photon_survival(&self, wo: Vec3) -> f32 {
        match self {
            Material::Plastic(p) => p.albedo_bound(wo),
            Material::RoughPlastic(p) => p.albedo_bound(wo),
            Material::Masked(m) => (max_component(m.rho()) + m.through()).min(1.0),
            Material::Principled(p) => p.albedo_bound(wo),
            Material::PrincipledThin(p) => p.albedo_bound(wo),
            _ => 1.0,
        }
    }

    #[inline(never)]
    pub(super) fn mitsuba_diffuse_albedo(&self, wo: Vec3) -> Color {
        match self {
            Material::Plastic(p) => p.diffuse_albedo(wo),
            Material::RoughPlastic(p) => p.diffuse_albedo(wo),
            Material::Masked(m) => m.rho(),
            Material::Principled(p) => p.diffuse_albedo(wo),
            Material::PrincipledThin(p) => p.diffuse_albedo(wo),
            _ => Color::ZERO,
        }
    }

    #[inline(never)]
    pub(super) fn mitsuba_eval(&self, wo: Vec3, wi: Vec3, entering: bool, mode: Transport) -> Color {
        match self {
            Material::RoughDielectric(d) => d.eval(wo, wi, entering, mode),
            Material::Principled(p) => p.eval(wo, wi, mode),
            Material::PrincipledThin(p) => p.eval(wo, wi),
            _ if !(wi.z > 0.0) => Color::ZERO,
            Material::RoughConductor(c) => c.eval(wo, wi),
            Material::Plastic(p) => p.eval(wo, wi),
            Material::RoughPlastic(p) => p.eval(wo, wi),
            Material::Masked(m) => m.rho() * std::f32::consts::FRAC_1_PI,
            _ => Color::ZERO,
        }
    }

    #[inline(never)]
    pub(super) fn mitsuba_pdf(&self, wo: Vec3, wi: Vec3, entering: bool) -> f32 {
        match self {
            Material::RoughConductor(c) => c.pdf(wo, wi),
            Material::RoughDielectric(d) => d.pdf(wo, wi, entering),
            Material::Plastic(p) => p.pdf(wo, wi),
            Material::RoughPlastic(p) => p.pdf(wo, wi),
            Material::Masked(m) => m.opacity * crate::sampling::cosine_hemisphere_pdf(wi),
            Material::Principled(p) => p.pdf(wo, wi),
            Material::PrincipledThin(p) => p.pdf(wo, wi),
            _ => 0.0,
        }
    }

    /// Smooth metal: one Fresnel mirror; a thin pane: its reflectance's
    /// share and straight through with the rest (no change of medium, no
    /// scale); a smooth plastic: its coat's Fresnel mirror.
    #[inline(never)]
    pub(super) fn mitsuba_specular_branches(&self, wo: Vec3) -> Branches {
        let mirror = |scale: Color| {
            if max_component(scale) > 0.0 {
                Branches::one(Branch { wi: reflect(wo), prob: 1.0, scale })
            } else {
                Branches::default()
            }
        };
        match self {
            Material::Conductor(c) => mirror(c.reflectance(wo.z)),
            Material::Plastic(p) => mirror(p.coat(wo)),
            Material::Masked(m) if m.through() > 0.0 => {
                Branches::one(Branch { wi: -wo, prob: m.through(), scale: Color::ONE })
            }
            Material::ThinDielectric(t) => {
                let r = t.reflectance(wo.z);
                let reflected = Branch { wi: reflect(wo), prob: r, scale: t.specular_reflectance };
                if r >= 1.0 {
                    Branches::one(Branch { prob: 1.0, ..reflected })
                } else {
                    let through = Branch { wi: -wo, prob: 1.0 - r, scale: t.specular_transmittance };
                    Branches { items: [Some(reflected), Some(through)] }
                }
            }
            _ => Branches::default(),
        }
    }

    #[inline(never)]
    pub(super) fn mitsuba_sample(&self, wo: Vec3, entering: bool, mode: Transport, rng: &mut Rng) -> Option<Scatter> {
        let specular = |b: Branch| Scatter { wi: b.wi, weight: b.scale, lobe: Lobe::Specular };
        let glossy = |(wi, weight): (Vec3, Color)| Scatter { wi, weight, lobe: Lobe::Glossy };
        match self {
            Material::Conductor(_) | Material::ThinDielectric(_) => {
                self.specular_branches(wo, entering, mode).choose(rng).map(specular)
            }
            Material::RoughConductor(c) => c.sample(wo, next_2d(rng)).map(glossy),
            Material::RoughDielectric(d) => {
                let u1 = rng.random::<f32>();
                d.sample(wo, entering, mode, u1, next_2d(rng)).map(glossy)
            }
            Material::Plastic(p) => {
                let (coat, chance) = p.choose_coat(wo, rng.random::<f32>());
                if coat {
                    let b = self.specular_branches(wo, entering, mode).choose(rng)?;
                    return Some(Scatter { weight: b.scale / chance, ..specular(b) });
                }
                let wi = cosine_hemisphere(next_2d(rng));
                let pdf = p.pdf(wo, wi);
                (pdf > 0.0).then(|| Scatter { wi, weight: p.eval(wo, wi) * (wi.z / pdf), lobe: Lobe::Diffuse })
            }
            Material::Masked(m) => {
                if rng.random::<f32>() < m.opacity {
                    // f cos / pdf = (opacity rho / pi) cos / (opacity cos / pi).
                    Some(Scatter { wi: cosine_hemisphere(next_2d(rng)), weight: m.rho, lobe: Lobe::Diffuse })
                } else {
                    Some(Scatter { wi: -wo, weight: Color::ONE, lobe: Lobe::Specular })
                }
            }
            Material::RoughPlastic(p) => {
                let u1 = rng.random::<f32>();
                let (wi, coat, weight) = p.sample(wo, u1, next_2d(rng))?;
                Some(Scatter { wi, weight, lobe: if coat { Lobe::Glossy } else { Lobe::Diffuse } })
            }
            Material::Principled(p) => {
                let u1 = rng.random::<f32>();
                let (wi, weight, diffuse) = p.sample(wo, mode, u1, next_2d(rng))?;
                Some(Scatter { wi, weight, lobe: if diffuse { Lobe::Diffuse } else { Lobe::Glossy } })
            }
            Material::PrincipledThin(p) => {
                let u1 = rng.random::<f32>();
                let (wi, weight, diffuse) = p.sample(wo, u1, next_2d(rng))?;
                Some(Scatter { wi, weight, lobe: if diffuse { Lobe::Diffuse } else { Lobe::Glossy } })
            }
            _ => None,
        }
    }
}
