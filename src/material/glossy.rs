//! A material's glossy lobes as photon mapping's estimators see them:
//! sampled like a path tracer, never stored in a photon map
//! (notes/method.md). Phong's lobe, a rough metal, rough glass (both of
//! its sides), a rough plastic's coat.
//!
//! A glossy lobe whose roughness is below [`CAUSTIC_ROUGHNESS`] *carries
//! caustics*: for the split of light paths between the estimators it
//! stands where a mirror or smooth glass would (caustic photons are traced
//! on through it and aimed at its object; final gathering from a diffuse
//! point passes through it counting nothing there). A rougher lobe scatters
//! light so widely that its caustics are a faint glow better found by
//! final gathering, which takes the light arriving at it by shadow rays.
//! Phong's lobe keeps its course-era rule: it never carries caustics.

use super::conductor::RoughConductor;
use super::dielectric::RoughDielectric;
use super::plastic::RoughPlastic;
use super::{Phong, Principled, PrincipledThin, Transport};
use crate::math::Color;
use crate::sampling::{next_2d, Rng};
use glam::{Vec2, Vec3};
use rand::RngExt;

/// Below this microfacet roughness (the larger alpha), a glossy lobe
/// carries caustics.
pub const CAUSTIC_ROUGHNESS: f32 = 0.3;

/// The glossy lobe of a material.
#[derive(Clone, Copy, Debug)]
pub enum Glossy<'a> {
    Phong(&'a Phong),
    Conductor(&'a RoughConductor),
    Dielectric(&'a RoughDielectric),
    /// A rough plastic's coat (its diffuse base is the material's diffuse lobe).
    Coat(&'a RoughPlastic),
    /// A principled BSDF's main reflection, transmission and clearcoat.
    Principled(&'a Principled),
    /// A thin principled BSDF's specular lobes and diffuse transmission.
    Thin(&'a PrincipledThin),
}

impl Glossy<'_> {
    /// The glossy lobes' BSDF alone (no diffuse part), for local `wo` and
    /// `wi` (below the surface: transmission, for rough glass).
    pub fn eval(&self, wo: Vec3, wi: Vec3, entering: bool, mode: Transport) -> Color {
        match self {
            Glossy::Phong(p) => p.glossy(wo, wi),
            Glossy::Conductor(c) => c.eval(wo, wi),
            Glossy::Dielectric(d) => d.eval(wo, wi, entering, mode),
            Glossy::Coat(p) => p.eval_coat(wo, wi),
            Glossy::Principled(p) => p.eval_glossy(wo, wi, mode),
            Glossy::Thin(p) => p.eval_glossy(wo, wi),
        }
    }

    /// The density (per solid angle) with which [`Self::sample`] returns
    /// `wi`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3, entering: bool) -> f32 {
        match self {
            Glossy::Phong(p) => p.glossy_pdf(wo, wi),
            Glossy::Conductor(c) => c.pdf(wo, wi),
            Glossy::Dielectric(d) => d.pdf(wo, wi, entering),
            Glossy::Coat(p) => p.coat_pdf(wo, wi),
            Glossy::Principled(p) => p.glossy_pdf(wo, wi),
            Glossy::Thin(p) => p.glossy_pdf(wo, wi),
        }
    }

    /// A direction from the glossy lobes alone and its weight f |cos| /
    /// pdf; `None` where the sample leaves on the wrong side. Phong's lobe
    /// draws two numbers, as it always has (the same images).
    pub fn sample(&self, wo: Vec3, entering: bool, mode: Transport, rng: &mut Rng) -> Option<(Vec3, Color)> {
        match self {
            Glossy::Phong(p) => p.sample_glossy(wo, next_2d(rng)),
            Glossy::Conductor(c) => c.sample(wo, next_2d(rng)),
            Glossy::Dielectric(d) => {
                let u1 = rng.random::<f32>();
                d.sample(wo, entering, mode, u1, next_2d(rng))
            }
            Glossy::Coat(p) => p.sample_coat(wo, next_2d(rng)),
            Glossy::Principled(p) => {
                let u1 = rng.random::<f32>();
                p.sample_glossy(wo, mode, u1, next_2d(rng))
            }
            Glossy::Thin(p) => {
                let u1 = rng.random::<f32>();
                p.sample_glossy(wo, u1, next_2d(rng))
            }
        }
    }

    /// [`Self::sample`] with the lobe's 2D sample (the microfacet normal,
    /// or the direction about the lobe's axis) given as `u`, a point of a
    /// stratified sequence; a lobe that also chooses (rough glass's
    /// Fresnel choice, a principled lobe's) draws that number from `rng`.
    /// The same warp: `u` uniform gives [`Self::pdf`].
    pub fn sample_at(
        &self,
        wo: Vec3,
        entering: bool,
        mode: Transport,
        u: Vec2,
        rng: &mut Rng,
    ) -> Option<(Vec3, Color)> {
        match self {
            Glossy::Phong(p) => p.sample_glossy(wo, u),
            Glossy::Conductor(c) => c.sample(wo, u),
            Glossy::Dielectric(d) => d.sample(wo, entering, mode, rng.random::<f32>(), u),
            Glossy::Coat(p) => p.sample_coat(wo, u),
            Glossy::Principled(p) => p.sample_glossy(wo, mode, rng.random::<f32>(), u),
            Glossy::Thin(p) => p.sample_glossy(wo, rng.random::<f32>(), u),
        }
    }

    /// [`Self::sample_split`] with the lobe's 2D sample given as `u`
    /// ([`Self::sample_at`]).
    pub fn sample_split_at(
        &self,
        wo: Vec3,
        entering: bool,
        mode: Transport,
        split: bool,
        u: Vec2,
        rng: &mut Rng,
    ) -> [Option<(Vec3, Color)>; 2] {
        match self {
            Glossy::Dielectric(d) if split => d.sample_both(wo, entering, mode, u),
            _ => [self.sample_at(wo, entering, mode, u, rng), None],
        }
    }

    /// Rough glass's two branches about one microfacet normal, each
    /// weighed by its Fresnel share ([`RoughDielectric::sample_both`]),
    /// where `split` asks for it; otherwise, or for any other lobe, one
    /// [`Self::sample`] (the same random numbers as without the question).
    pub fn sample_split(
        &self,
        wo: Vec3,
        entering: bool,
        mode: Transport,
        split: bool,
        rng: &mut Rng,
    ) -> [Option<(Vec3, Color)>; 2] {
        match self {
            Glossy::Dielectric(d) if split => d.sample_both(wo, entering, mode, next_2d(rng)),
            _ => [self.sample(wo, entering, mode, rng), None],
        }
    }

    /// Rough glass's Fresnel reflectance for `wo` about the surface's own
    /// normal (zero for any other lobe).
    pub fn reflectance_about_normal(&self, wo: Vec3, entering: bool) -> f32 {
        match self {
            Glossy::Dielectric(d) => crate::optics::fresnel_dielectric(wo.z.abs(), 1.0, d.eta(entering)),
            _ => 0.0,
        }
    }

    /// Whether [`Self::sample_split`] splits (rough glass).
    pub fn splits(&self) -> bool {
        matches!(self, Glossy::Dielectric(_))
    }

    /// Where a material has both a glossy lobe and specular branches (only
    /// Phong), the chance that a path going on through one of them takes
    /// a branch: their albedos' shares.
    pub fn specular_share(&self) -> f32 {
        match self {
            Glossy::Phong(p) => {
                let [_, g, m] = p.lobe_weights();
                m / (g + m)
            }
            _ => 0.0,
        }
    }

    /// Whether the lobe stands for a specular one in the split of light
    /// paths (see the module's documentation).
    pub fn carries_caustics(&self) -> bool {
        let roughness = match self {
            Glossy::Phong(_) => return false,
            Glossy::Conductor(c) => c.microfacet.roughness(),
            Glossy::Dielectric(d) => d.microfacet.roughness(),
            Glossy::Coat(p) => p.microfacet.roughness(),
            Glossy::Principled(p) => p.microfacet().roughness(),
            Glossy::Thin(p) => p.microfacet().roughness(),
        };
        roughness < CAUSTIC_ROUGHNESS
    }

    /// Whether the lobe lets light through the surface.
    pub fn transmits(&self) -> bool {
        match self {
            Glossy::Dielectric(_) => true,
            Glossy::Principled(p) => p.transmits(),
            Glossy::Thin(p) => p.transmits(),
            _ => false,
        }
    }
}
