//! Dielectric boundaries beside the smooth glass: Mitsuba 3's
//! `roughdielectric` and `thindielectric` (src/bsdfs/roughdielectric.cpp,
//! thindielectric.cpp). Indices: `int_ior` inside (the side the geometric
//! normal points away from), `ext_ior` outside; Mitsuba's defaults are
//! BK7 (1.5046) and air (1.000277).
//!
//! The rough one is Walter et al.'s (2007) microfacet BSDF, with `eta` the
//! ratio of the far side's index to `wo`'s side's:
//! * reflection F D G / (4 cos_o cos_i), h = normalize(wo + wi);
//! * transmission (1 - F) D G eta^2 |wo.h| |wi.h| / (cos_o |cos_i|
//!   (wo.h + eta wi.h)^2) (eq. 21), h = normalize(wo + eta wi) turned up,
//!   times 1 / eta^2 for radiance (a camera path crossing into the denser
//!   side; Veach 1997, ch. 5, as Mitsuba adds);
//!
//! sampled through the normals visible from `wo` (Heitz 2014), reflecting
//! with Fresnel's share F(wo . m): a sample weighs G1(wi, m) (times 1 /
//! eta^2 across, for radiance). Its white furnace loses only what Smith's
//! single-scattering model loses (light that would scatter again among the
//! microfacets), Heitz et al. 2016: a few percent at alpha 0.5, none at 0.

use super::microfacet::Microfacet;
use super::Transport;
use crate::math::Color;
use crate::optics::fresnel_dielectric;
use glam::{Vec2, Vec3};

/// Rough glass: one glossy lobe on each side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    pub microfacet: Microfacet,
    pub int_ior: f32,
    pub ext_ior: f32,
    pub specular_reflectance: Color,
    pub specular_transmittance: Color,
}

impl RoughDielectric {
    /// The far side's index over `wo`'s side's.
    pub fn eta(&self, entering: bool) -> f32 {
        if entering {
            self.int_ior / self.ext_ior
        } else {
            self.ext_ior / self.int_ior
        }
    }

    /// The microfacet normal (turned up) that takes `wo` into `wi`, and
    /// whether that is a reflection.
    fn half(wo: Vec3, wi: Vec3, eta: f32) -> (Vec3, bool) {
        let reflect = wi.z > 0.0;
        let h = if reflect { wo + wi } else { wo + eta * wi };
        let h = h.normalize();
        (if h.z < 0.0 { -h } else { h }, reflect)
    }

    /// The BSDF for local `wo` (above) and `wi` (above: reflection; below:
    /// transmission into the far side).
    pub fn eval(&self, wo: Vec3, wi: Vec3, entering: bool, mode: Transport) -> Color {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return Color::ZERO;
        }
        let eta = self.eta(entering);
        let (h, reflect) = Self::half(wo, wi, eta);
        let mf = &self.microfacet;
        let d = mf.d(h);
        let g = mf.g(wo, wi, h);
        if !(d > 0.0 && g > 0.0) {
            return Color::ZERO;
        }
        let f = fresnel_dielectric(wo.dot(h), 1.0, eta);
        if reflect {
            return self.specular_reflectance * (f * d * g / (4.0 * wo.z * wi.z));
        }
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let denom = oh + eta * ih;
        let scale = match mode {
            Transport::Radiance => 1.0 / (eta * eta),
            Transport::Importance => 1.0,
        };
        let v = scale * (1.0 - f) * d * g * eta * eta * (oh * ih).abs() / (wo.z * wi.z.abs() * denom * denom);
        self.specular_transmittance * v
    }

    /// The density of [`Self::sample`]'s directions, both sides.
    pub fn pdf(&self, wo: Vec3, wi: Vec3, entering: bool) -> f32 {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return 0.0;
        }
        let eta = self.eta(entering);
        let (h, reflect) = Self::half(wo, wi, eta);
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        // The sides the microfacet and the macro surface agree on, as
        // Smith's G1 demands in eval and sample.
        if !(oh > 0.0 && ih * wi.z > 0.0) {
            return 0.0;
        }
        let f = fresnel_dielectric(oh, 1.0, eta);
        let jacobian = if reflect {
            1.0 / (4.0 * ih)
        } else {
            let denom = oh + eta * ih;
            eta * eta * ih.abs() / (denom * denom)
        };
        let choice = if reflect { f } else { 1.0 - f };
        self.microfacet.visible_pdf(wo, h) * choice * jacobian
    }

    /// A direction about a visible microfacet normal, reflected with
    /// Fresnel's share and refracted otherwise, and its weight f |cos| /
    /// pdf. `u1` chooses, `u` the normal. `None` where the direction leaves
    /// on the wrong side of the macro surface.
    pub fn sample(&self, wo: Vec3, entering: bool, mode: Transport, u1: f32, u: Vec2) -> Option<(Vec3, Color)> {
        let (m, c, f) = self.facet(wo, entering, u)?;
        if u1 < f {
            self.reflected(wo, m, c, 1.0)
        } else {
            // f < 1: no total internal reflection here.
            self.refracted(wo, m, c, self.eta(entering), mode, 1.0)
        }
    }

    /// Both of [`Self::sample`]'s branches about one visible microfacet
    /// normal (`u`), each weighed by its share of the choice (F reflected,
    /// 1 - F refracted) instead of chosen by it: their sum's mean is one
    /// sample's, without the noise of the choice. `None` for a branch that
    /// leaves on the wrong side or has no share.
    pub fn sample_both(&self, wo: Vec3, entering: bool, mode: Transport, u: Vec2) -> [Option<(Vec3, Color)>; 2] {
        let Some((m, c, f)) = self.facet(wo, entering, u) else { return [None, None] };
        let reflected = if f > 0.0 { self.reflected(wo, m, c, f) } else { None };
        let refracted = if f < 1.0 { self.refracted(wo, m, c, self.eta(entering), mode, 1.0 - f) } else { None };
        [reflected, refracted]
    }

    /// A visible microfacet normal m for `wo`, wo . m and Fresnel's
    /// reflectance there.
    fn facet(&self, wo: Vec3, entering: bool, u: Vec2) -> Option<(Vec3, f32, f32)> {
        if !(wo.z > 0.0) {
            return None;
        }
        let m = self.microfacet.sample_visible(wo, u);
        let c = wo.dot(m);
        (c > 0.0).then(|| (m, c, fresnel_dielectric(c, 1.0, self.eta(entering))))
    }

    /// `wo` reflected about m (c = wo . m), its weight times `share`.
    fn reflected(&self, wo: Vec3, m: Vec3, c: f32, share: f32) -> Option<(Vec3, Color)> {
        let wi = 2.0 * c * m - wo;
        (wi.z > 0.0).then(|| (wi, self.specular_reflectance * (share * self.microfacet.g1(wi, m))))
    }

    /// `wo` refracted about m (c = wo . m, below the critical angle), its
    /// weight times `share`.
    fn refracted(&self, wo: Vec3, m: Vec3, c: f32, eta: f32, mode: Transport, share: f32) -> Option<(Vec3, Color)> {
        let sin2_t = (1.0 - c * c) / (eta * eta);
        let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
        let wi = (-wo / eta + (c / eta - cos_t) * m).normalize();
        if !(wi.z < 0.0) {
            return None;
        }
        let scale = match mode {
            Transport::Radiance => 1.0 / (eta * eta),
            Transport::Importance => 1.0,
        };
        Some((wi, self.specular_transmittance * (share * scale * self.microfacet.g1(wi, m))))
    }
}

/// A thin sheet of glass (a window pane, a soap film): light passes
/// straight through or is reflected, the sheet's internal reflections
/// summed: R' = R + (1 - R)^2 R / (1 - R^2) = 2R / (1 + R), R Fresnel's
/// reflectance at the incidence, the same from either side (Mitsuba's
/// thindielectric).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinDielectric {
    pub int_ior: f32,
    pub ext_ior: f32,
    pub specular_reflectance: Color,
    pub specular_transmittance: Color,
}

impl ThinDielectric {
    /// The sheet's reflectance R' at incidence `cos`.
    pub fn reflectance(&self, cos: f32) -> f32 {
        let r = fresnel_dielectric(cos, self.ext_ior, self.int_ior);
        if r < 1.0 {
            2.0 * r / (1.0 + r)
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::microfacet::Distribution;

    /// Both branches about one normal are what the Fresnel choice between
    /// them gives on average over the choosing number: the same
    /// directions, and weights that sum to the choice's mean weight.
    #[test]
    fn both_branches_are_the_choice_averaged() {
        for (entering, alpha) in [(true, 0.1), (false, 0.1), (false, 0.4), (true, 0.6)] {
            let glass = RoughDielectric {
                microfacet: Microfacet::new(Distribution::Ggx, alpha, alpha),
                int_ior: 1.5,
                ext_ior: 1.0,
                specular_reflectance: Color::new(0.9, 0.8, 0.7),
                specular_transmittance: Color::new(0.6, 0.7, 0.8),
            };
            for k in 0..50 {
                let t = 0.05 + 1.4 * k as f32 / 50.0;
                let wo = Vec3::new(t.sin(), 0.0, t.cos());
                let u = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 * 0.414_214).fract());
                let both = glass.sample_both(wo, entering, Transport::Radiance, u);
                let (mut mean, n) = (Color::ZERO, 2000);
                for i in 0..n {
                    let u1 = (i as f32 + 0.5) / n as f32;
                    if let Some((wi, w)) = glass.sample(wo, entering, Transport::Radiance, u1, u) {
                        let branch = both[(wi.z < 0.0) as usize].expect("a branch the choice takes");
                        assert!(branch.0.distance(wi) < 1e-6, "{wi} against {}", branch.0);
                        mean += w / n as f32;
                    }
                }
                let sum = both.iter().flatten().fold(Color::ZERO, |a, b| a + b.1);
                assert!((sum - mean).abs().max_element() < 2e-3, "wo {wo}: {sum} against {mean}");
            }
        }
    }
}
