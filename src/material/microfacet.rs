//! Microfacet distributions, as Mitsuba 3 defines them
//! (`include/mitsuba/render/microfacet.h`): Beckmann and GGX
//! (Trowbridge–Reitz), with roughness `alpha_u` along the frame's first
//! tangent and `alpha_v` along its second (isotropic where they are equal).
//!
//! * D(m), the distribution of normals (Walter et al. 2007, eqs. 25 and
//!   33, with the anisotropic forms of Heitz 2014, eqs. 80 and 85);
//! * Smith's masking G1(v, m) = 1 / (1 + Lambda(v)) (Heitz 2014, eqs. 72
//!   and 86) and the separable shadowing-masking G = G1(wo) G1(wi), zero
//!   where a direction sees the back of the microfacet;
//! * sampling of the normals visible from `wo` with density
//!   D_wo(m) = G1(wo, m) max(0, wo . m) D(m) / wo.z: GGX by Heitz's
//!   (2018) hemisphere method, Beckmann by the slope sampling of Heitz and
//!   d'Eon (2014) with Jakob's numerical inversion (as Mitsuba does).
//!
//! Beckmann's Lambda is evaluated exactly (with erf), where Mitsuba uses a
//! rational fit within 0.35% of it; the exact one is the normalisation of
//! the visible normals sampled here, so the sampler and its pdf agree.
//!
//! Directions are local (normal +z), unit length; `wo` lies above the
//! surface (`wo.z > 0`).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Mitsuba's alpha is clamped to at least this (a smooth surface is the
/// smooth material's, not a microfacet model's).
pub const MIN_ALPHA: f32 = 1e-4;

/// Which distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    Beckmann,
    Ggx,
}

impl Distribution {
    /// Mitsuba's names: "beckmann" (its default), "ggx".
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "beckmann" => Some(Distribution::Beckmann),
            "ggx" => Some(Distribution::Ggx),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Distribution::Beckmann => "beckmann",
            Distribution::Ggx => "ggx",
        }
    }
}

/// A rough surface's microfacets: the distribution and its roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Microfacet {
    pub distribution: Distribution,
    pub alpha_u: f32,
    pub alpha_v: f32,
}

impl Microfacet {
    /// Roughness below [`MIN_ALPHA`] is raised to it, as in Mitsuba.
    pub fn new(distribution: Distribution, alpha_u: f32, alpha_v: f32) -> Self {
        Microfacet { distribution, alpha_u: alpha_u.max(MIN_ALPHA), alpha_v: alpha_v.max(MIN_ALPHA) }
    }

    pub fn isotropic(distribution: Distribution, alpha: f32) -> Self {
        Self::new(distribution, alpha, alpha)
    }

    /// The larger roughness: what decides how photon mapping treats the
    /// lobe (notes/method.md).
    pub fn roughness(&self) -> f32 {
        self.alpha_u.max(self.alpha_v)
    }

    /// D(m): the density of microfacet normals per unit projected area,
    /// normalised so that the integral of D(m) m.z over the hemisphere is 1.
    pub fn d(&self, m: Vec3) -> f32 {
        if !(m.z > 0.0) {
            return 0.0;
        }
        let (x, y) = (m.x / self.alpha_u, m.y / self.alpha_v);
        let z2 = m.z * m.z;
        let d = match self.distribution {
            Distribution::Beckmann => (-(x * x + y * y) / z2).exp() / (PI * self.alpha_u * self.alpha_v * z2 * z2),
            Distribution::Ggx => {
                let s = x * x + y * y + z2;
                1.0 / (PI * self.alpha_u * self.alpha_v * s * s)
            }
        };
        if d.is_finite() {
            d
        } else {
            0.0
        }
    }

    /// Smith's Lambda(v): the masked projected area's share, for the
    /// roughness projected on v's azimuth.
    pub fn lambda(&self, v: Vec3) -> f32 {
        let xy = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if xy == 0.0 {
            return 0.0;
        }
        let tan2 = xy / (v.z * v.z);
        match self.distribution {
            Distribution::Ggx => 0.5 * ((1.0 + tan2).sqrt() - 1.0),
            Distribution::Beckmann => {
                // a = 1 / (alpha tan theta) (Walter et al. 2007, eq. 27).
                let a = 1.0 / tan2.sqrt();
                0.5 * (erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * PI.sqrt())
            }
        }
    }

    /// Smith's masking of microfacet normal `m` seen from `v`; zero where
    /// `v` would see the microfacet's back (or the surface's).
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        1.0 / (1.0 + self.lambda(v))
    }

    /// The separable shadowing-masking term G1(wo, m) G1(wi, m).
    pub fn g(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// A microfacet normal visible from `wo` (`wo.z > 0`), with density
    /// [`Self::visible_pdf`]; `u` uniform in [0, 1)^2.
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        match self.distribution {
            Distribution::Ggx => self.sample_ggx(wo, u),
            Distribution::Beckmann => self.sample_beckmann(wo, u),
        }
    }

    /// The density of [`Self::sample_visible`] per unit solid angle of m:
    /// G1(wo, m) max(0, wo . m) D(m) / wo.z (Heitz 2014, eq. 38).
    pub fn visible_pdf(&self, wo: Vec3, m: Vec3) -> f32 {
        let c = wo.dot(m);
        if !(c > 0.0) || !(wo.z > 0.0) {
            return 0.0;
        }
        self.g1(wo, m) * c * self.d(m) / wo.z
    }

    /// Heitz (2018), "Sampling the GGX distribution of visible normals":
    /// stretch `wo` to the unit-roughness configuration, sample the
    /// projected area of the hemisphere seen from it (a disk, its far half
    /// squashed by the foreshortening), lift to the hemisphere, unstretch.
    fn sample_ggx(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let v = Vec3::new(self.alpha_u * wo.x, self.alpha_v * wo.y, wo.z).normalize();
        let len2 = v.x * v.x + v.y * v.y;
        let t1 = if len2 > 0.0 { Vec3::new(-v.y, v.x, 0.0) / len2.sqrt() } else { Vec3::X };
        let t2 = v.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let (p1, p2) = (r * phi.cos(), r * phi.sin());
        let s = 0.5 * (1.0 + v.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let n = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * v;
        Vec3::new(self.alpha_u * n.x, self.alpha_v * n.y, n.z.max(1e-6)).normalize()
    }

    /// Heitz and d'Eon (2014): in the stretched configuration the visible
    /// slopes for incidence theta are sampled from their marginal in x (its
    /// CDF inverted in the erf domain by Newton's method, as Jakob rewrote
    /// the paper's routine) and a Gaussian in y; rotated to `wo`'s azimuth
    /// and unstretched.
    fn sample_beckmann(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let v = Vec3::new(self.alpha_u * wo.x, self.alpha_v * wo.y, wo.z).normalize();
        let sin_theta = (1.0 - v.z * v.z).max(0.0).sqrt();
        let (cos_phi, sin_phi) = if sin_theta > 1e-7 { (v.x / sin_theta, v.y / sin_theta) } else { (1.0, 0.0) };
        let slope = beckmann_visible_slope_11(v.z, u);
        let sx = (cos_phi * slope.x - sin_phi * slope.y) * self.alpha_u;
        let sy = (sin_phi * slope.x + cos_phi * slope.y) * self.alpha_v;
        Vec3::new(-sx, -sy, 1.0).normalize()
    }
}

/// A slope of the unit-roughness Beckmann surface, visible from incidence
/// cos theta, with azimuth 0. The x slope's CDF, in t = erf(x):
/// C(t) = (1 + t + tan(theta) exp(-erfinv(t)^2) / sqrt(pi)) / norm, with
/// norm = 1 + erf(cot theta) + tan(theta) exp(-cot^2 theta) / sqrt(pi).
fn beckmann_visible_slope_11(cos_theta: f32, u: Vec2) -> Vec2 {
    let u = u.clamp(Vec2::splat(1e-6), Vec2::splat(1.0 - 1e-6));
    let tan_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt() / cos_theta;
    let cot_theta = 1.0 / tan_theta;
    let inv_sqrt_pi = 1.0 / PI.sqrt();
    let top = erf(cot_theta);
    // A start from the closed form at grazing incidence, the hardest case.
    let mut t = top - (top + 1.0) * erf((-u.x.ln()).sqrt());
    let target = u.x * (1.0 + top + inv_sqrt_pi * tan_theta * (-cot_theta * cot_theta).exp());
    for _ in 0..3 {
        let x = erfinv(t);
        let value = 1.0 + t + inv_sqrt_pi * tan_theta * (-x * x).exp() - target;
        let derivative = 1.0 - x * tan_theta;
        t -= value / derivative;
    }
    let t = t.clamp(-1.0 + 1e-7, 1.0 - 1e-7);
    Vec2::new(erfinv(t), erfinv(2.0 * u.y - 1.0))
}

/// The error function, within 1.2e-7 (Numerical Recipes' Chebyshev fit of
/// erfc, W. J. Cody's form; the formula, written anew).
pub fn erf(x: f32) -> f32 {
    let x = x as f64;
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98 + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let erfc = t * poly.exp();
    let r = 1.0 - erfc;
    (if x >= 0.0 { r } else { -r }) as f32
}

/// The inverse error function on (-1, 1): Giles' (2012) single-precision
/// polynomials, then one Newton step on erf.
pub fn erfinv(y: f32) -> f32 {
    let w = -((1.0 - y) * (1.0 + y)).ln();
    let x = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_4e-8f32;
        for c in [
            3.432_739_4e-7,
            -3.523_387_7e-6,
            -4.391_506_5e-6,
            2.185_808_7e-4,
            -1.253_725e-3,
            -4.177_681_6e-3,
            0.246_640_72,
            1.501_409_4,
        ] {
            p = c + p * w;
        }
        p * y
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -2.000_214_3e-4f32;
        for c in [
            1.009_505_6e-4,
            1.349_343_2e-3,
            -3.673_428_4e-3,
            5.739_507_7e-3,
            -7.622_461e-3,
            9.438_870_5e-3,
            1.001_674,
            2.832_976_8,
        ] {
            p = c + p * w;
        }
        p * y
    };
    if !x.is_finite() {
        return x;
    }
    // d erf / dx = 2 / sqrt(pi) exp(-x^2).
    let err = erf(x) - y;
    x - err / (2.0 / PI.sqrt() * (-x * x).exp())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};

    fn all() -> Vec<Microfacet> {
        let mut v = Vec::new();
        for d in [Distribution::Beckmann, Distribution::Ggx] {
            for (au, av) in [(0.05, 0.05), (0.3, 0.3), (0.8, 0.8), (0.1, 0.5), (0.6, 0.15)] {
                v.push(Microfacet::new(d, au, av));
            }
        }
        v
    }

    /// The projected microfacet area is the macro surface's: the integral
    /// of D(m) cos theta_m is 1; and the visible normals' projected area
    /// is the surface's seen from v: the integral of G1 (v.m) D is v.z
    /// (Heitz 2014, eqs. 4 and 18), which checks Lambda against D.
    #[test]
    fn d_and_smith_masking_are_normalised() {
        for mf in all() {
            let n = 400_000;
            // Importance by a cosine power where D is sharp: plain uniform
            // directions would miss a lobe of alpha 0.05.
            let projected = visible_integral(&mf, Vec3::Z, n);
            assert!((projected - 1.0).abs() < 0.01, "{mf:?}: int D cos = {projected}");
            for v in [Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.8, 0.3f32).normalize()] {
                let got = visible_integral(&mf, v, n);
                assert!((got - v.z as f64).abs() < 0.01 * v.z as f64, "{mf:?} v {v}: {got} vs {}", v.z);
            }
        }
    }

    /// The integral of G1(v, m) (v.m)+ D(m) over m, by sampling m from a
    /// wide Beckmann-like proposal: normals sampled by the visible-normal
    /// routine of an independent isotropic lobe of the larger alpha, mixed
    /// with uniform ones.
    fn visible_integral(mf: &Microfacet, v: Vec3, n: usize) -> f64 {
        let proposal = Microfacet::isotropic(Distribution::Ggx, mf.alpha_u.max(mf.alpha_v) * 1.5);
        let mut rng = stream(11, Domain::Camera, 1);
        let mut sum = 0.0f64;
        for i in 0..n {
            let m = if i % 2 == 0 {
                proposal.sample_visible(Vec3::Z, next_2d(&mut rng))
            } else {
                uniform_cone(next_2d(&mut rng), 0.0)
            };
            let pdf = 0.5 * proposal.visible_pdf(Vec3::Z, m) as f64 + 0.5 / (2.0 * std::f64::consts::PI);
            let f = if v == Vec3::Z { mf.d(m) * m.z } else { mf.g1(v, m) * v.dot(m).max(0.0) * mf.d(m) };
            sum += f as f64 / pdf;
        }
        sum / n as f64
    }

    #[test]
    fn ggx_masking_matches_its_closed_form() {
        // Isotropic GGX: G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2)) (Walter et al. 2007, eq. 34).
        let mf = Microfacet::isotropic(Distribution::Ggx, 0.4);
        let v = Vec3::new(0.8, 0.0, 0.6);
        let tan2 = (0.8f32 / 0.6).powi(2);
        let want = 2.0 / (1.0 + (1.0 + 0.16 * tan2).sqrt());
        assert!((mf.g1(v, Vec3::Z) - want).abs() < 1e-6);
        // Seen from below the microfacet: masked.
        assert_eq!(mf.g1(v, Vec3::new(-0.9, 0.0, 0.1).normalize()), 0.0);
    }

    #[test]
    fn erf_and_its_inverse() {
        for (x, want) in
            [(0.0f32, 0.0f32), (0.5, 0.520_499_9), (1.0, 0.842_700_8), (2.0, 0.995_322_3), (-1.5, -0.966_105_1)]
        {
            assert!((erf(x) - want).abs() < 3e-7, "erf({x}) = {} vs {want}", erf(x));
        }
        for y in [-0.999_9f32, -0.9, -0.3, 0.0, 0.2, 0.7, 0.99, 0.999_99] {
            let x = erfinv(y);
            assert!((erf(x) - y).abs() < 1e-6, "erf(erfinv({y})) = {}", erf(x));
        }
    }
}
