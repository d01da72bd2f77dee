//! A diffuse base under a dielectric coat: Mitsuba 3's `plastic` and
//! `roughplastic` (src/bsdfs/plastic.cpp, roughplastic.cpp), after Weidlich
//! and Wilkie (2007). Light is reflected by the coat (smooth: a mirror of
//! Fresnel's share F(wo); rough: a microfacet lobe, Walter et al. 2007,
//! times `specular_reflectance`), or crosses it, scatters diffusely in the
//! base, and leaves through it:
//!
//! f_d = rho' (1 - F(wo)) (1 - F(wi)) / (pi eta^2),
//! rho' = rho / (1 - R_int)  (`nonlinear`: rho / (1 - rho R_int)),
//!
//! with R_int the coat's diffuse reflectance from inside; for the rough
//! coat, 1 - F becomes the coat's transmittance t(cos) of light spread by
//! its microfacets, tabulated over cos (64 values, as Mitsuba). Mitsuba's
//! defaults: int_ior polypropylene (1.49), ext_ior air (1.000277),
//! diffuse_reflectance 0.5, specular_reflectance 1, nonlinear false;
//! roughplastic: Beckmann, alpha 0.1, isotropic only.
//!
//! The smooth coat's diffuse reflectances are the fits Mitsuba uses
//! (Egan and Hilgeman 1973 below eta 1, d'Eon and Irving 2011 above); the
//! rough coat's are integrated here over the visible normals.

use super::microfacet::Microfacet;
use crate::math::{max_component, Color};
use crate::optics::fresnel_dielectric;
use crate::sampling::cosine_hemisphere_pdf;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Mutex;

/// The hemispherical (cosine-weighted) reflectance of a smooth dielectric
/// boundary of relative index `eta` for light arriving evenly from all
/// directions: Mitsuba's fits (Egan and Hilgeman 1973 for eta < 1, d'Eon
/// and Irving 2011 otherwise).
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv + eta * (eta * -1.4399 + 0.7099) + 0.6681
    } else {
        let mut p = -1.36881f32;
        for c in [4.98554, -7.80989, 6.75335, -3.4793, 0.919317] {
            p = c + p * inv;
        }
        p
    }
}

/// A smooth plastic: a specular coat over a diffuse base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    pub diffuse: Color,
    pub specular: Color,
    /// int_ior / ext_ior.
    pub eta: f32,
    pub nonlinear: bool,
}

impl Plastic {
    fn base(&self) -> Color {
        let r_int = fresnel_diffuse_reflectance(1.0 / self.eta);
        let denom = if self.nonlinear { Color::ONE - self.diffuse * r_int } else { Color::splat(1.0 - r_int) };
        self.diffuse / denom / (self.eta * self.eta)
    }

    fn fresnel(&self, cos: f32) -> f32 {
        fresnel_dielectric(cos, 1.0, self.eta)
    }

    /// The coat's mirror reflection towards `wo`: F(wo) times the specular
    /// reflectance.
    pub fn coat(&self, wo: Vec3) -> Color {
        self.specular * self.fresnel(wo.z)
    }

    /// The chance the coat's mirror is chosen (Mitsuba's: Fresnel's share
    /// steered by the mean specular and diffuse reflectances).
    fn specular_chance(&self, wo: Vec3) -> f32 {
        let (s, d) = (mean(self.specular), mean(self.diffuse));
        let w = if s + d > 0.0 { s / (s + d) } else { 0.5 };
        let f = self.fresnel(wo.z);
        let (ps, pd) = (f * w, (1.0 - f) * (1.0 - w));
        if ps + pd > 0.0 {
            ps / (ps + pd)
        } else {
            0.0
        }
    }

    /// The diffuse lobe's BRDF.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return Color::ZERO;
        }
        self.base() * ((1.0 - self.fresnel(wo.z)) * (1.0 - self.fresnel(wi.z)) / PI)
    }

    /// The density of the diffuse lobe's samples, its chance included.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        (1.0 - self.specular_chance(wo)) * cosine_hemisphere_pdf(wi)
    }

    /// Whether the coat's mirror is chosen for a sample with `u`, and the
    /// chance of that choice.
    pub fn choose_coat(&self, wo: Vec3, u: f32) -> (bool, f32) {
        let p = self.specular_chance(wo);
        (u < p, p)
    }

    /// What the diffuse lobe reflects towards `wo` of light arriving evenly
    /// from above: rho' (1 - F(wo)) (1 - F_dr,ext) / eta^2.
    pub fn diffuse_albedo(&self, wo: Vec3) -> Color {
        self.base() * ((1.0 - self.fresnel(wo.z)) * (1.0 - fresnel_diffuse_reflectance(self.eta)))
    }

    /// The fraction of light reflected towards `wo`, largest channel (its
    /// photons' chance to go on).
    pub fn albedo_bound(&self, wo: Vec3) -> f32 {
        max_component(self.coat(wo) + self.diffuse_albedo(wo)).min(1.0)
    }
}

/// The resolution of the rough coat's transmittance table.
const TABLE: usize = 64;

/// A rough plastic: a glossy coat over a diffuse base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlastic {
    pub microfacet: Microfacet,
    pub diffuse: Color,
    pub specular: Color,
    pub eta: f32,
    pub nonlinear: bool,
    /// The coat's transmittance t(cos) at cos = i / 63 and its diffuse
    /// reflectance from inside: computed once per (distribution, alpha,
    /// eta) and shared (interned), so that the material stays a small Copy
    /// value.
    coat: &'static CoatTable,
}

/// What a rough coat lets through, tabulated.
#[derive(Debug, PartialEq)]
pub struct CoatTable {
    transmittance: [f32; TABLE],
    /// R_int: the cosine-weighted mean reflectance from inside.
    internal_reflectance: f32,
    /// 2 * integral of t(mu) mu: what light arriving evenly passes.
    mean_transmittance: f32,
}

impl RoughPlastic {
    pub fn new(microfacet: Microfacet, diffuse: Color, specular: Color, eta: f32, nonlinear: bool) -> Self {
        RoughPlastic { microfacet, diffuse, specular, eta, nonlinear, coat: coat_table(microfacet, eta) }
    }

    fn base(&self) -> Color {
        let r = self.coat.internal_reflectance;
        let denom = if self.nonlinear { Color::ONE - self.diffuse * r } else { Color::splat(1.0 - r) };
        self.diffuse / denom / (self.eta * self.eta)
    }

    /// The coat's transmittance at `cos`, linearly interpolated.
    pub fn transmittance(&self, cos: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (TABLE - 1) as f32;
        let i = (x as usize).min(TABLE - 2);
        let t = &self.coat.transmittance;
        t[i] + (t[i + 1] - t[i]) * (x - i as f32)
    }

    /// The coat's microfacet lobe alone.
    pub fn eval_coat(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return Color::ZERO;
        }
        let h = (wo + wi).normalize();
        let d = self.microfacet.d(h);
        if !(d > 0.0) {
            return Color::ZERO;
        }
        let f = fresnel_dielectric(wo.dot(h), 1.0, self.eta);
        self.specular * (f * d * self.microfacet.g(wo, wi, h) / (4.0 * wo.z * wi.z))
    }

    /// The coat's lobe's density: D(h) G1(wo, h) / (4 cos_o) (of
    /// [`Self::sample_coat`]'s directions, above the surface).
    pub fn coat_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        if !(wo.dot(h) > 0.0 && wi.dot(h) > 0.0) {
            return 0.0;
        }
        self.microfacet.d(h) * self.microfacet.g1(wo, h) / (4.0 * wo.z)
    }

    /// The diffuse base's BRDF.
    pub fn eval_diffuse(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return Color::ZERO;
        }
        self.base() * (self.transmittance(wo.z) * self.transmittance(wi.z) / PI)
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        self.eval_coat(wo, wi) + self.eval_diffuse(wo, wi)
    }

    fn coat_chance(&self, wo: Vec3) -> f32 {
        let (s, d) = (mean(self.specular), mean(self.diffuse));
        let w = if s + d > 0.0 { s / (s + d) } else { 0.5 };
        let t = self.transmittance(wo.z);
        let (ps, pd) = ((1.0 - t) * w, t * (1.0 - w));
        if ps + pd > 0.0 {
            ps / (ps + pd)
        } else {
            0.0
        }
    }

    /// The mixture's density: the coat's lobe and the cosine lobe, each by
    /// its chance.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let p = self.coat_chance(wo);
        p * self.coat_pdf(wo, wi) + (1.0 - p) * cosine_hemisphere_pdf(wi)
    }

    /// A direction from the mixture (the coat chosen with `u1` below its
    /// chance), whether it came from the coat, and its weight f cos / pdf
    /// over both lobes.
    pub fn sample(&self, wo: Vec3, u1: f32, u: Vec2) -> Option<(Vec3, bool, Color)> {
        if !(wo.z > 0.0) {
            return None;
        }
        let coat = u1 < self.coat_chance(wo);
        let wi = if coat {
            let m = self.microfacet.sample_visible(wo, u);
            2.0 * wo.dot(m) * m - wo
        } else {
            crate::sampling::cosine_hemisphere(u)
        };
        let pdf = self.pdf(wo, wi);
        if !(wi.z > 0.0 && pdf > 0.0) {
            return None;
        }
        Some((wi, coat, self.eval(wo, wi) * (wi.z / pdf)))
    }

    /// The coat's lobe alone, sampled: its weight F(wo . m) G1(wi, m) times
    /// the specular reflectance.
    pub fn sample_coat(&self, wo: Vec3, u: Vec2) -> Option<(Vec3, Color)> {
        if !(wo.z > 0.0) {
            return None;
        }
        let m = self.microfacet.sample_visible(wo, u);
        let c = wo.dot(m);
        let wi = 2.0 * c * m - wo;
        if !(wi.z > 0.0 && c > 0.0) {
            return None;
        }
        let f = fresnel_dielectric(c, 1.0, self.eta);
        Some((wi, self.specular * (f * self.microfacet.g1(wi, m))))
    }

    pub fn diffuse_albedo(&self, wo: Vec3) -> Color {
        self.base() * (self.transmittance(wo.z) * self.coat.mean_transmittance)
    }

    pub fn albedo_bound(&self, wo: Vec3) -> f32 {
        let coat = max_component(self.specular) * (1.0 - self.transmittance(wo.z));
        (coat + max_component(self.diffuse_albedo(wo))).min(1.0)
    }
}

fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// The interned tables, one per (distribution, alpha, eta) a scene uses.
static TABLES: Mutex<Vec<(Microfacet, u32, &'static CoatTable)>> = Mutex::new(Vec::new());

fn coat_table(microfacet: Microfacet, eta: f32) -> &'static CoatTable {
    let mut tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(t) = tables.iter().find(|(m, e, _)| *m == microfacet && *e == eta.to_bits()) {
        return t.2;
    }
    let table: &'static CoatTable = Box::leak(Box::new(compute_coat(microfacet, eta)));
    tables.push((microfacet, eta.to_bits(), table));
    table
}

/// The coat's single-scattering transmittance and reflectance for light
/// arriving at cos mu, integrated over the normals visible from it (a
/// midpoint grid of the sampler's square): t(mu) = E[(1 - F(wo . m))
/// G1(wt, m)] over refractions wt going down; the reflectance from inside
/// E[F G1(wr, m)] with 1 / eta. R_int = 2 mean(r(mu) mu) over the table's
/// mu, as Mitsuba averages it.
fn compute_coat(mf: Microfacet, eta: f32) -> CoatTable {
    const GRID: usize = 48;
    let through = |mu: f32, eta: f32, reflect: bool| -> f32 {
        let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        let mut sum = 0.0f64;
        for i in 0..GRID {
            for j in 0..GRID {
                let u = Vec2::new((i as f32 + 0.5) / GRID as f32, (j as f32 + 0.5) / GRID as f32);
                let m = mf.sample_visible(wo, u);
                let c = wo.dot(m);
                if !(c > 0.0) {
                    continue;
                }
                let f = fresnel_dielectric(c, 1.0, eta);
                let value = if reflect {
                    let wr = 2.0 * c * m - wo;
                    if wr.z > 0.0 {
                        f * mf.g1(wr, m)
                    } else {
                        0.0
                    }
                } else {
                    let sin2_t = (1.0 - c * c) / (eta * eta);
                    if sin2_t >= 1.0 {
                        0.0
                    } else {
                        let wt = (-wo / eta + (c / eta - (1.0 - sin2_t).sqrt()) * m).normalize();
                        if wt.z < 0.0 {
                            (1.0 - f) * mf.g1(wt, m)
                        } else {
                            0.0
                        }
                    }
                };
                sum += value as f64;
            }
        }
        (sum / (GRID * GRID) as f64) as f32
    };
    let mus: Vec<f32> = (0..TABLE).map(|i| (i as f32 / (TABLE - 1) as f32).max(1e-6)).collect();
    let transmittance: [f32; TABLE] = std::array::from_fn(|i| through(mus[i], eta, false));
    let internal_reflectance =
        2.0 * mus.iter().map(|&mu| through(mu, 1.0 / eta, true) * mu).sum::<f32>() / TABLE as f32;
    let mean_transmittance = 2.0 * mus.iter().zip(&transmittance).map(|(&mu, &t)| t * mu).sum::<f32>() / TABLE as f32;
    CoatTable { transmittance, internal_reflectance, mean_transmittance }
}
