//! Mitsuba 3's `principled` BSDF (src/bsdfs/principled.cpp), Burley's
//! Disney BSDF as Mitsuba defines it, its parameters and defaults: four
//! lobes, weighted by `metallic` and `spec_trans` (brdf = (1 - metallic)
//! (1 - spec_trans), bsdf = (1 - metallic) spec_trans):
//!
//! * **diffuse** ([`super::disney::diffuse_shape`]) times brdf base / pi,
//!   with the **sheen** sheen (1 - metallic) F(cos_d) lerp(1, tint,
//!   sheen_tint): photon mapping's diffuse lobe;
//! * **main specular reflection**, GGX of alpha from roughness and
//!   anisotropic: F D G / (4 cos_o cos_i), F the blend of the dielectric
//!   Fresnel (weight (1 - metallic)(1 - spec_tint)), Schlick of the base
//!   colour (weight metallic) and Schlick of the tinted dielectric
//!   reflectance (weight (1 - metallic) spec_tint); from the back, bsdf
//!   times the dielectric Fresnel alone;
//! * **specular transmission**, Walter et al.'s microfacet refraction with
//!   the same normals, times sqrt(base) bsdf (1 / eta^2 for radiance);
//! * **clearcoat**, 0.25 clearcoat F_schlick(0.04) D_GTR1 G_GGX(0.25),
//!   with no division by the cosines (as Mitsuba has it).
//!
//! The three last are the glossy lobe (`material::Glossy`). The diffuse
//! lobe, the sheen and the clearcoat are on the front only: the material
//! is one-sided, its back ([`Principled::back`]) the side its index is
//! seen from inside (inside Mitsuba's `twosided`, both sides are fronts). Sampling picks
//! a lobe with Mitsuba's chances (diffuse brdf, clearcoat 0.25 clearcoat,
//! specular 1, each times its rate; the specular's share split between
//! reflection and transmission by the Fresnel at the sampled normal), and
//! weighs the direction by the whole BSDF over the whole density.
//!
//! Mitsuba evaluates the sheen wherever the diffuse lobe is evaluated for
//! any lane of a vector of rays: its vectorised variants (the references)
//! add it even where the diffuse weight brdf is zero; so does this.

use super::disney::{self, alphas, clearcoat_g1, schlick, schlick_r0, Gtr1, Rates};
use super::microfacet::{Distribution, Microfacet};
use super::Transport;
use crate::math::Color;
use crate::optics::fresnel_dielectric;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Mitsuba's `principled` at one point (its textures read there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Principled {
    pub base_color: Color,
    pub roughness: f32,
    pub anisotropic: f32,
    pub metallic: f32,
    pub spec_trans: f32,
    /// Interior over exterior index (from `eta`, or from `specular`).
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub clearcoat: f32,
    pub clearcoat_gloss: f32,
    /// Sampling rates: diffuse, main specular, clearcoat.
    pub rates: Rates,
    /// Whether this is the back of the surface (its lobes there: the
    /// specular reflection and transmission alone).
    pub back: bool,
}

/// The specular lobes' geometry for a pair of directions.
struct Half {
    h: Vec3,
    reflect: bool,
    /// Whether the microfacet and the macro surface agree on the sides.
    compatible: bool,
    /// Fresnel's dielectric reflectance at the microfacet.
    f: f32,
    /// |d h / d wi|.
    jacobian: f32,
}

impl Principled {
    /// Mitsuba's defaults: base 0.5, roughness 0.5, specular 0.5 (eta 1.5),
    /// everything else 0.
    pub fn new(base_color: Color) -> Self {
        Principled {
            base_color,
            roughness: 0.5,
            anisotropic: 0.0,
            metallic: 0.0,
            spec_trans: 0.0,
            eta: 1.5,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            clearcoat: 0.0,
            clearcoat_gloss: 0.0,
            rates: Rates::default(),
            back: false,
        }
    }

    /// The index `specular` stands for: 2 / (1 - sqrt(0.08 specular)) - 1.
    pub fn eta_of_specular(specular: f32) -> f32 {
        2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
    }

    fn brdf(&self) -> f32 {
        (1.0 - self.metallic) * (1.0 - self.spec_trans)
    }

    fn bsdf(&self) -> f32 {
        (1.0 - self.metallic) * self.spec_trans
    }

    /// The main specular lobes' microfacets.
    pub fn microfacet(&self) -> Microfacet {
        let (ax, ay) = alphas(self.roughness, self.anisotropic);
        Microfacet::new(Distribution::Ggx, ax, ay)
    }

    /// The far side's index over `wo`'s.
    fn eta_path(&self) -> f32 {
        if !self.back {
            self.eta
        } else {
            1.0 / self.eta
        }
    }

    fn half(&self, wo: Vec3, wi: Vec3) -> Half {
        let eta = self.eta_path();
        let reflect = wi.z > 0.0;
        let h = if reflect { wo + wi } else { wo + eta * wi }.normalize_or_zero();
        let h = if h.z < 0.0 { -h } else { h };
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let compatible = oh > 0.0 && if reflect { ih > 0.0 } else { ih < 0.0 };
        let jacobian = if reflect {
            1.0 / (4.0 * ih.abs())
        } else {
            let denom = oh + eta * ih;
            eta * eta * ih.abs() / (denom * denom)
        };
        Half { h, reflect, compatible, f: fresnel_dielectric(oh, 1.0, eta), jacobian }
    }

    /// The lobes' chances (diffuse, clearcoat, specular reflection,
    /// specular transmission) given the Fresnel reflectance `f` at the
    /// microfacet, normalised.
    fn chances(&self, f: f32) -> [f32; 4] {
        let [rate_diffuse, rate_spec, rate_coat, _] = self.rates.get();
        let front = !self.back;
        let bsdf = self.bsdf();
        if !front && !(bsdf > 0.0) {
            return [0.0; 4];
        }
        let p = if front {
            [
                self.brdf() * rate_diffuse,
                0.25 * self.clearcoat * rate_coat,
                rate_spec * (1.0 - bsdf * (1.0 - f)),
                rate_spec * bsdf * (1.0 - f),
            ]
        } else {
            [0.0, 0.0, f, if bsdf > 0.0 { 1.0 - f } else { 0.0 }]
        };
        let total: f32 = p.iter().sum();
        if total > 0.0 {
            p.map(|x| x / total)
        } else {
            [0.0; 4]
        }
    }

    /// The Fresnel term of the main reflection at a microfacet seen at
    /// `cos` (> 0), whose dielectric reflectance is `f`.
    fn fresnel(&self, f: f32, cos: f32, front: bool) -> Color {
        if !front {
            return Color::splat(self.bsdf() * f);
        }
        let m = self.metallic;
        let mut value = Color::splat((1.0 - m) * (1.0 - self.spec_tint) * f);
        if m > 0.0 {
            value += m * schlick(self.base_color, cos, self.eta);
        }
        if self.spec_tint > 0.0 {
            let r0 = disney::tint(self.base_color) * schlick_r0(self.eta);
            value += (1.0 - m) * self.spec_tint * schlick(r0, cos, self.eta);
        }
        value
    }

    /// The diffuse lobe with the sheen (front only).
    pub fn eval_diffuse(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(!self.back && wo.z > 0.0 && wi.z > 0.0) {
            return Color::ZERO;
        }
        let h = (wo + wi).normalize_or_zero();
        let cos_d = h.dot(wi);
        let mut value = Color::ZERO;
        let brdf = self.brdf();
        if brdf > 0.0 {
            let shape = disney::diffuse_shape(wi.z, wo.z, cos_d, self.roughness, self.flatness);
            value += self.base_color * (brdf * FRAC_1_PI * shape);
        }
        if self.sheen > 0.0 && self.metallic < 1.0 {
            value += self.sheen_color() * disney::schlick_weight(cos_d.abs());
        }
        value
    }

    fn sheen_color(&self) -> Color {
        let tint = Color::ONE + (disney::tint(self.base_color) - Color::ONE) * self.sheen_tint;
        tint * (self.sheen * (1.0 - self.metallic))
    }

    /// The glossy lobes: main reflection, transmission, clearcoat.
    pub fn eval_glossy(&self, wo: Vec3, wi: Vec3, mode: Transport) -> Color {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return Color::ZERO;
        }
        let front = !self.back;
        let bsdf = self.bsdf();
        if !front && !(bsdf > 0.0) {
            return Color::ZERO;
        }
        let half = self.half(wo, wi);
        if !half.compatible {
            return Color::ZERO;
        }
        let Half { h, f, .. } = half;
        let mf = self.microfacet();
        let d = mf.d(h);
        let g = mf.g(wo, wi, h);
        let mut value = Color::ZERO;
        if half.reflect {
            if f > 0.0 {
                value += self.fresnel(f, wo.dot(h), front) * (d * g / (4.0 * wo.z * wi.z));
            }
            if front && self.clearcoat > 0.0 {
                let fcc = schlick(Color::splat(0.04), wo.dot(h), self.eta).x;
                let dcc = Gtr1::from_gloss(self.clearcoat_gloss).d(h);
                let gcc = clearcoat_g1(wo, h) * clearcoat_g1(wi, h);
                value += Color::splat(0.25 * self.clearcoat * fcc * dcc * gcc);
            }
        } else if bsdf > 0.0 && f < 1.0 {
            let eta = self.eta_path();
            let (oh, ih) = (wo.dot(h), wi.dot(h));
            let denom = oh + eta * ih;
            let scale = match mode {
                Transport::Radiance => 1.0 / (eta * eta),
                Transport::Importance => 1.0,
            };
            let t = scale * (1.0 - f) * d * g * eta * eta * (oh * ih).abs() / (wo.z * wi.z.abs() * denom * denom);
            value += self.base_color.max(Color::ZERO).powf(0.5) * (bsdf * t);
        }
        value
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, mode: Transport) -> Color {
        self.eval_diffuse(wo, wi) + self.eval_glossy(wo, wi, mode)
    }

    /// The density of each lobe's directions, unweighted: (diffuse,
    /// clearcoat, reflection, transmission), and the chances.
    fn densities(&self, wo: Vec3, wi: Vec3) -> ([f32; 4], [f32; 4]) {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return ([0.0; 4], [0.0; 4]);
        }
        let half = self.half(wo, wi);
        let chances = self.chances(half.f);
        let mut p = [0.0; 4];
        if half.reflect {
            p[0] = cosine_hemisphere_pdf(wi);
        }
        if half.compatible {
            let visible = self.microfacet().visible_pdf(wo, half.h) * half.jacobian;
            if half.reflect {
                p[2] = visible;
                p[1] = Gtr1::from_gloss(self.clearcoat_gloss).pdf(half.h) * half.jacobian;
            } else {
                p[3] = visible;
            }
        }
        (p, chances)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (p, c) = self.densities(wo, wi);
        (0..4).map(|i| p[i] * c[i]).sum()
    }

    /// The glossy lobes' density alone (their chances renormalised).
    pub fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (p, c) = self.densities(wo, wi);
        let total = c[1] + c[2] + c[3];
        if !(total > 0.0) {
            return 0.0;
        }
        (p[1] * c[1] + p[2] * c[2] + p[3] * c[3]) / total
    }

    /// Whether the glossy lobes reflect or transmit anything.
    pub fn has_glossy(&self) -> bool {
        let c = self.chances(0.5);
        c[1] + c[2] + c[3] > 0.0
    }

    /// A direction from the lobe `u1` picks (all four, or the glossy
    /// ones alone), and whether it came from the diffuse lobe; `None`
    /// where it leaves on the wrong side or the lobe gives none.
    fn draw(&self, wo: Vec3, glossy_only: bool, u1: f32, u: Vec2) -> Option<(Vec3, bool)> {
        if !(wo.z > 0.0) {
            return None;
        }
        let mf = self.microfacet();
        let m = mf.sample_visible(wo, u);
        let eta = self.eta_path();
        let f = fresnel_dielectric(wo.dot(m), 1.0, eta);
        let mut c = self.chances(f);
        if glossy_only {
            c[0] = 0.0;
            let total = c[1] + c[2] + c[3];
            if !(total > 0.0) {
                return None;
            }
            c = c.map(|x| x / total);
        }
        // A microfacet sample counts where the microfacet and the macro
        // surface agree on the sides (Mitsuba drops the others; the
        // density has none).
        let reflected = |m: Vec3| {
            let wi = 2.0 * wo.dot(m) * m - wo;
            (wo.dot(m) > 0.0 && wi.dot(m) > 0.0 && wi.z > 0.0).then_some((wi, false))
        };
        if u1 < c[0] {
            Some((cosine_hemisphere(u), true))
        } else if u1 < c[0] + c[1] {
            reflected(Gtr1::from_gloss(self.clearcoat_gloss).sample(u))
        } else if u1 < c[0] + c[1] + c[2] {
            reflected(m)
        } else {
            let cos = wo.dot(m);
            let sin2_t = (1.0 - cos * cos) / (eta * eta);
            if !(cos > 0.0) || sin2_t >= 1.0 {
                return None;
            }
            let cos_t = (1.0 - sin2_t).sqrt();
            let wi = (-wo / eta + (cos / eta - cos_t) * m).normalize();
            (wi.z < 0.0 && wi.dot(m) < 0.0).then_some((wi, false))
        }
    }

    /// A direction from the whole BSDF, its weight f |cos| / pdf and
    /// whether it came from the diffuse lobe.
    pub fn sample(&self, wo: Vec3, mode: Transport, u1: f32, u: Vec2) -> Option<(Vec3, Color, bool)> {
        let (wi, diffuse) = self.draw(wo, false, u1, u)?;
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some((wi, self.eval(wo, wi, mode) * (wi.z.abs() / pdf), diffuse))
    }

    /// A direction from the glossy lobes alone and its weight over them.
    pub fn sample_glossy(&self, wo: Vec3, mode: Transport, u1: f32, u: Vec2) -> Option<(Vec3, Color)> {
        let (wi, _) = self.draw(wo, true, u1, u)?;
        let pdf = self.glossy_pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some((wi, self.eval_glossy(wo, wi, mode) * (wi.z.abs() / pdf)))
    }

    /// The diffuse lobe's weight where it reflects anything (front only).
    pub fn diffuse_rho(&self) -> Option<Color> {
        if self.back {
            return None;
        }
        let rho = self.base_color * self.brdf() + self.sheen_color();
        (rho.max_element() > 0.0).then_some(rho)
    }

    /// What the diffuse lobe and the sheen reflect towards `wo` of light
    /// arriving evenly from above.
    pub fn diffuse_albedo(&self, wo: Vec3) -> Color {
        if self.back {
            return Color::ZERO;
        }
        let mut a = self.base_color * (self.brdf() * disney::diffuse_albedo(wo.z, self.roughness, self.flatness));
        if self.sheen > 0.0 && self.metallic < 1.0 {
            a += self.sheen_color() * (std::f32::consts::PI * disney::sheen_albedo(wo.z));
        }
        a
    }

    /// A bound on the fraction of light reflected or transmitted towards
    /// `wo` (the chance a photon goes on).
    pub fn albedo_bound(&self, wo: Vec3) -> f32 {
        let diffuse = self.diffuse_albedo(wo).max_element();
        let f = fresnel_dielectric(wo.z, 1.0, self.eta_path());
        let reflected = self.fresnel(f, wo.z, !self.back).max_element();
        let through = self.bsdf() * (1.0 - f) * self.base_color.max_element().max(0.0).sqrt();
        (diffuse + reflected + through + 0.25 * self.clearcoat).clamp(0.05, 1.0)
    }

    /// Whether light passes through.
    pub fn transmits(&self) -> bool {
        self.bsdf() > 0.0
    }
}
