//! Mitsuba 3's `principledthin` BSDF (src/bsdfs/principledthin.cpp): the
//! principled BSDF of a thin sheet (a leaf, paper, a curtain), the same
//! from both sides, light leaving on either:
//!
//! * **diffuse reflection** ([`super::disney::diffuse_shape`]) times
//!   (1 - spec_trans)(1 - diff_trans / 2) base / pi, and the **sheen**
//!   sheen (1 - spec_trans)(1 - diff_trans / 2) F(cos_d) lerp(1, tint,
//!   sheen_tint): photon mapping's diffuse lobe;
//! * **specular reflection** spec_trans F D G / (4 cos_o cos_i), GGX of
//!   alpha from roughness and anisotropic, F the dielectric Fresnel of
//!   `eta` blended with Schlick's of the tinted colour by `spec_tint`;
//! * **specular transmission** spec_trans base (1 - F) D' G' / (4 cos_o
//!   |cos_i|), a reflection turned through the sheet, with the roughness
//!   scaled by (0.65 eta - 0.35) (Burley 2015, figure 15);
//! * **diffuse transmission** (1 - spec_trans)(diff_trans / 2) base / pi
//!   through the sheet.
//!
//! The last three are the glossy lobe (`material::Glossy`): photons are
//! stored on the side they arrive at, so light diffusely transmitted
//! through a sheet is traced on, not estimated from the far side's map.
//! Sampling picks a lobe with Mitsuba's chances (spec_trans / 2 each for
//! the specular ones, (1 - spec_trans)(1 - diff_trans / 2) and (1 -
//! spec_trans) diff_trans / 2 for the diffuse ones, each times its rate)
//! and weighs the direction by the whole BSDF over the whole density.
//! `diff_trans` runs over [0, 2], as in Mitsuba.

use super::disney::{self, alphas, schlick, schlick_r0, Rates};
use super::microfacet::{Distribution, Microfacet};
use crate::math::Color;
use crate::optics::fresnel_dielectric;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Mitsuba's `principledthin` at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledThin {
    pub base_color: Color,
    pub roughness: f32,
    pub anisotropic: f32,
    pub spec_trans: f32,
    /// The sheet's index (relative to both sides).
    pub eta: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    /// In [0, 2].
    pub diff_trans: f32,
    /// Sampling rates: specular reflection, specular transmission,
    /// diffuse transmission, diffuse reflection.
    pub rates: Rates,
}

impl PrincipledThin {
    /// Mitsuba's defaults: base 0.5, roughness 0.5, eta 1.5, the rest 0.
    pub fn new(base_color: Color) -> Self {
        PrincipledThin {
            base_color,
            roughness: 0.5,
            anisotropic: 0.0,
            spec_trans: 0.0,
            eta: 1.5,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            diff_trans: 0.0,
            rates: Rates::default(),
        }
    }

    fn microfacets(&self) -> (Microfacet, Microfacet) {
        let (ax, ay) = alphas(self.roughness, self.anisotropic);
        let (sx, sy) = alphas((0.65 * self.eta - 0.35) * self.roughness, self.anisotropic);
        (Microfacet::new(Distribution::Ggx, ax, ay), Microfacet::new(Distribution::Ggx, sx, sy))
    }

    /// The main lobe's microfacets (what decides how photon mapping treats
    /// the glossy lobes).
    pub fn microfacet(&self) -> Microfacet {
        self.microfacets().0
    }

    fn dt(&self) -> f32 {
        0.5 * self.diff_trans
    }

    /// The lobes' chances: specular reflection, specular transmission,
    /// diffuse reflection, diffuse transmission, normalised.
    fn chances(&self) -> [f32; 4] {
        let [r_sr, r_st, r_dt, r_dr] = self.rates.get();
        let (st, dt) = (self.spec_trans, self.dt());
        let p = [st * r_sr / 2.0, st * r_st / 2.0, r_dr * (1.0 - st) * (1.0 - dt), r_dt * (1.0 - st) * dt];
        let total: f32 = p.iter().sum();
        if total > 0.0 {
            p.map(|x| x / total)
        } else {
            [0.0; 4]
        }
    }

    /// The half vector of the specular lobes: of `wo` and `wi` mirrored to
    /// `wo`'s side; whether it agrees with the sides of both.
    fn half(wo: Vec3, wi: Vec3) -> (Vec3, bool) {
        let mirrored = Vec3::new(wi.x, wi.y, wi.z.abs());
        let h = (wo + mirrored).normalize_or_zero();
        let ih = wi.dot(h);
        (h, wo.dot(h) > 0.0 && if wi.z > 0.0 { ih > 0.0 } else { ih < 0.0 })
    }

    /// The diffuse reflection with the sheen.
    pub fn eval_diffuse(&self, wo: Vec3, wi: Vec3) -> Color {
        let (st, dt) = (self.spec_trans, self.dt());
        if !(wo.z > 0.0 && wi.z > 0.0 && st < 1.0 && dt < 1.0) {
            return Color::ZERO;
        }
        let cos_d = (wo + wi).normalize_or_zero().dot(wi);
        let shape = disney::diffuse_shape(wi.z, wo.z, cos_d, self.roughness, self.flatness);
        let mut value = self.base_color * ((1.0 - st) * (1.0 - dt) * FRAC_1_PI * shape);
        if self.sheen > 0.0 {
            value += self.sheen_color() * disney::schlick_weight(cos_d.abs());
        }
        value
    }

    fn sheen_color(&self) -> Color {
        let tint = Color::ONE + (disney::tint(self.base_color) - Color::ONE) * self.sheen_tint;
        tint * (self.sheen * (1.0 - self.spec_trans) * (1.0 - self.dt()))
    }

    /// The specular lobes and the diffuse transmission.
    pub fn eval_glossy(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return Color::ZERO;
        }
        let (st, dt) = (self.spec_trans, self.dt());
        let mut value = Color::ZERO;
        if wi.z < 0.0 && st < 1.0 && dt > 0.0 {
            value += self.base_color * ((1.0 - st) * dt * FRAC_1_PI);
        }
        if st > 0.0 {
            let (h, compatible) = Self::half(wo, wi);
            if compatible {
                let (main, scaled) = self.microfacets();
                let oh = wo.dot(h);
                let f = fresnel_dielectric(oh, 1.0, self.eta);
                if wi.z > 0.0 {
                    let fresnel = if self.spec_tint > 0.0 {
                        let r0 = disney::tint(self.base_color) * schlick_r0(self.eta);
                        Color::splat(f) + (schlick(r0, oh, self.eta) - Color::splat(f)) * self.spec_tint
                    } else {
                        Color::splat(f)
                    };
                    let dg = main.d(h) * main.g(wo, wi, h);
                    value += fresnel * (st * dg / (4.0 * wo.z * wi.z));
                } else {
                    let dg = scaled.d(h) * scaled.g(wo, wi, h);
                    value += self.base_color * (st * (1.0 - f) * dg / (4.0 * wo.z * wi.z.abs()));
                }
            }
        }
        value
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.eval_diffuse(wo, wi) + self.eval_glossy(wo, wi)
    }

    /// Each lobe's density, unweighted, in the order of [`Self::chances`].
    fn densities(&self, wo: Vec3, wi: Vec3) -> [f32; 4] {
        if !(wo.z > 0.0) || wi.z == 0.0 {
            return [0.0; 4];
        }
        let mut p = [0.0; 4];
        if wi.z > 0.0 {
            p[2] = cosine_hemisphere_pdf(wi);
        } else {
            p[3] = cosine_hemisphere_pdf(-wi);
        }
        if self.spec_trans > 0.0 {
            let (h, compatible) = Self::half(wo, wi);
            if compatible {
                let (main, scaled) = self.microfacets();
                // d h / d wi of the reflection that the transmission mirrors.
                let jacobian = 1.0 / (4.0 * wo.dot(h));
                if wi.z > 0.0 {
                    p[0] = main.visible_pdf(wo, h) * jacobian;
                } else {
                    p[1] = scaled.visible_pdf(wo, h) * jacobian;
                }
            }
        }
        p
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (p, c) = (self.densities(wo, wi), self.chances());
        (0..4).map(|i| p[i] * c[i]).sum()
    }

    /// The glossy lobes' density alone (their chances renormalised).
    pub fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (p, c) = (self.densities(wo, wi), self.chances());
        let total = c[0] + c[1] + c[3];
        if !(total > 0.0) {
            return 0.0;
        }
        (p[0] * c[0] + p[1] * c[1] + p[3] * c[3]) / total
    }

    /// Whether the glossy lobes reflect or transmit anything.
    pub fn has_glossy(&self) -> bool {
        let c = self.chances();
        c[0] + c[1] + c[3] > 0.0
    }

    fn draw(&self, wo: Vec3, glossy_only: bool, u1: f32, u: Vec2) -> Option<(Vec3, bool)> {
        if !(wo.z > 0.0) {
            return None;
        }
        let mut c = self.chances();
        if glossy_only {
            c[2] = 0.0;
            let total: f32 = c.iter().sum();
            if !(total > 0.0) {
                return None;
            }
            c = c.map(|x| x / total);
        }
        // A specular sample counts where the microfacet and the sheet agree
        // on the sides (Mitsuba drops the others; the density has none).
        let specular = |mf: Microfacet, through: bool| {
            let m = mf.sample_visible(wo, u);
            let r = 2.0 * wo.dot(m) * m - wo;
            let wi = if through { Vec3::new(r.x, r.y, -r.z) } else { r };
            let ih = wi.dot(m);
            let kept = wo.dot(m) > 0.0 && if through { wi.z < 0.0 && ih < 0.0 } else { wi.z > 0.0 && ih > 0.0 };
            kept.then_some((wi, false))
        };
        if u1 < c[0] {
            specular(self.microfacets().0, false)
        } else if u1 < c[0] + c[1] {
            specular(self.microfacets().1, true)
        } else if u1 < c[0] + c[1] + c[2] {
            Some((cosine_hemisphere(u), true))
        } else {
            Some((-cosine_hemisphere(u), false))
        }
    }

    /// A direction from the whole BSDF, its weight f |cos| / pdf and
    /// whether it came from the diffuse reflection.
    pub fn sample(&self, wo: Vec3, u1: f32, u: Vec2) -> Option<(Vec3, Color, bool)> {
        let (wi, diffuse) = self.draw(wo, false, u1, u)?;
        let pdf = self.pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some((wi, self.eval(wo, wi) * (wi.z.abs() / pdf), diffuse))
    }

    /// A direction from the glossy lobes alone and its weight over them.
    pub fn sample_glossy(&self, wo: Vec3, u1: f32, u: Vec2) -> Option<(Vec3, Color)> {
        let (wi, _) = self.draw(wo, true, u1, u)?;
        let pdf = self.glossy_pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some((wi, self.eval_glossy(wo, wi) * (wi.z.abs() / pdf)))
    }

    pub fn diffuse_rho(&self) -> Option<Color> {
        let (st, dt) = (self.spec_trans, self.dt());
        let rho = self.base_color * ((1.0 - st) * (1.0 - dt)).max(0.0) + self.sheen_color();
        (st < 1.0 && dt < 1.0 && rho.max_element() > 0.0).then_some(rho)
    }

    /// What the diffuse reflection and the sheen reflect towards `wo` of
    /// light arriving evenly from above.
    pub fn diffuse_albedo(&self, wo: Vec3) -> Color {
        let (st, dt) = (self.spec_trans, self.dt());
        if !(st < 1.0 && dt < 1.0) {
            return Color::ZERO;
        }
        let mut a =
            self.base_color * ((1.0 - st) * (1.0 - dt) * disney::diffuse_albedo(wo.z, self.roughness, self.flatness));
        if self.sheen > 0.0 {
            a += self.sheen_color() * (std::f32::consts::PI * disney::sheen_albedo(wo.z));
        }
        a
    }

    /// A rough bound on the fraction of light sent on (a photon's chance
    /// to go on).
    pub fn albedo_bound(&self, wo: Vec3) -> f32 {
        let (st, dt) = (self.spec_trans, self.dt());
        let base = self.base_color.max_element().max(0.0);
        let diffuse = self.diffuse_albedo(wo).max_element() + (1.0 - st) * dt * base;
        (diffuse + st * base.max(1.0)).clamp(0.05, 1.0)
    }

    /// Whether light passes through.
    pub fn transmits(&self) -> bool {
        self.spec_trans > 0.0 || self.dt() > 0.0
    }
}
