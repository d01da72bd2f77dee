//! Metals, as Mitsuba 3's `conductor` and `roughconductor` define them
//! (src/bsdfs/conductor.cpp, roughconductor.cpp): Fresnel reflectance of a
//! complex index eta + i k per RGB channel ([`fresnel_conductor`]), times
//! `specular_reflectance`. Mitsuba's defaults: eta = 0, k = 1 (a perfect
//! mirror), specular_reflectance = 1; the rough one Beckmann, alpha = 0.1.
//!
//! The rough one is Walter et al.'s (2007) microfacet BRDF
//! f = F(wo . h) D(h) G(wo, wi, h) / (4 cos_o cos_i), h the half vector,
//! sampled through the normals visible from `wo` (Heitz 2014, 2018): its
//! pdf is D(h) G1(wo, h) / (4 cos_o) and a sample weighs F G1(wi, h).

use super::microfacet::Microfacet;
use crate::math::Color;
use crate::optics::fresnel_conductor;
use glam::{Vec2, Vec3};

/// A smooth metal: a perfect mirror whose reflectance follows Fresnel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    pub eta: Color,
    pub k: Color,
    pub specular: Color,
}

impl Conductor {
    /// The fraction reflected at incidence `cos`.
    pub fn reflectance(&self, cos: f32) -> Color {
        self.specular * fresnel_conductor(cos, self.eta, self.k)
    }
}

/// A rough metal (one glossy lobe).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    pub microfacet: Microfacet,
    pub eta: Color,
    pub k: Color,
    pub specular: Color,
}

impl RoughConductor {
    fn fresnel(&self, cos: f32) -> Color {
        self.specular * fresnel_conductor(cos, self.eta, self.k)
    }

    /// The BRDF for local `wo`, `wi` (zero unless both lie above).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return Color::ZERO;
        }
        let h = (wo + wi).normalize();
        let d = self.microfacet.d(h);
        if !(d > 0.0) {
            return Color::ZERO;
        }
        let g = self.microfacet.g(wo, wi, h);
        self.fresnel(wo.dot(h)) * (d * g / (4.0 * wo.z * wi.z))
    }

    /// The density of [`Self::sample`]'s directions.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        if !(wo.dot(h) > 0.0 && wi.dot(h) > 0.0) {
            return 0.0;
        }
        self.microfacet.d(h) * self.microfacet.g1(wo, h) / (4.0 * wo.z)
    }

    /// A direction reflected about a visible microfacet normal, and its
    /// weight f cos / pdf = F(wo . m) G1(wi, m); `None` below the surface.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<(Vec3, Color)> {
        if !(wo.z > 0.0) {
            return None;
        }
        let m = self.microfacet.sample_visible(wo, u);
        let c = wo.dot(m);
        let wi = 2.0 * c * m - wo;
        if !(wi.z > 0.0) || !(c > 0.0) {
            return None;
        }
        Some((wi, self.fresnel(c) * self.microfacet.g1(wi, m)))
    }
}
