//! What Mitsuba 3's `principled` and `principledthin` share
//! (src/bsdfs/principledhelpers.h), after Burley's "Physically based
//! shading at Disney" (2012) and "Extending the Disney BRDF to a BSDF with
//! integrated subsurface scattering" (2015): Schlick's Fresnel, the
//! roughness-to-alpha map, the clearcoat's GTR1 distribution, the
//! diffuse lobe (Lambert shaped by Schlick weights, retro-reflection, fake
//! subsurface, sheen) with its albedo, and the sampling rates.
//!
//! Conventions as the rest of `material`: local frame, `wo` towards the
//! viewer (`wo.z > 0`), `wi` the scattered direction.

use crate::math::Color;
use std::f32::consts::PI;
use std::sync::{Mutex, OnceLock};

/// Schlick's weight (1 - cos)^5, cos clamped to [0, 1].
#[inline]
pub fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's reflectance at normal incidence of a boundary of relative
/// index `eta`: ((eta - 1) / (eta + 1))^2.
#[inline]
pub fn schlick_r0(eta: f32) -> f32 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// Schlick's approximation R0 + (1 - R0) w for light meeting a microfacet
/// at `cos` (> 0) from the side where the relative index is `eta`: w of
/// the incident cosine into a denser medium, of the refracted one out of
/// it (1 past the critical angle), as Mitsuba's `calc_schlick`.
#[inline]
pub fn schlick(r0: Color, cos: f32, eta: f32) -> Color {
    let w = if eta > 1.0 {
        schlick_weight(cos.abs())
    } else {
        let cos_t2 = 1.0 - (1.0 - cos * cos) / (eta * eta);
        schlick_weight(cos_t2.max(0.0).sqrt())
    };
    r0 + (Color::ONE - r0) * w
}

/// Luminance of a linear sRGB colour (Mitsuba's `luminance`).
#[inline]
pub fn luminance(c: Color) -> f32 {
    crate::texture::luminance(c)
}

/// A colour's hue at unit luminance (white where it is black): the tint of
/// the sheen and the tinted specular.
#[inline]
pub fn tint(base: Color) -> Color {
    let lum = luminance(base);
    if lum > 0.0 {
        base / lum
    } else {
        Color::ONE
    }
}

/// The main lobe's (alpha_u, alpha_v) from `roughness` and `anisotropic`
/// (Burley 2012, as Mitsuba's `calc_dist_params`): roughness squared,
/// stretched by sqrt(1 - 0.9 anisotropic), at least 0.001.
#[inline]
pub fn alphas(roughness: f32, anisotropic: f32) -> (f32, f32) {
    let r2 = roughness * roughness;
    let aspect = (1.0 - 0.9 * anisotropic).max(0.0).sqrt();
    if aspect == 1.0 {
        let a = r2.max(0.001);
        return (a, a);
    }
    ((r2 / aspect).max(0.001), (r2 * aspect).max(0.001))
}

/// The clearcoat's normal distribution, Burley's GTR1 (isotropic), with
/// alpha lerp(0.1, 0.001, clearcoat_gloss).
#[derive(Clone, Copy, Debug)]
pub struct Gtr1 {
    alpha: f32,
}

impl Gtr1 {
    pub fn from_gloss(gloss: f32) -> Self {
        Gtr1 { alpha: 0.1 + (0.001 - 0.1) * gloss }
    }

    /// D(m): (alpha^2 - 1) / (pi ln(alpha^2) (1 + (alpha^2 - 1) cos^2)).
    #[inline]
    pub fn d(&self, m: glam::Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let d = (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * m.z * m.z));
        if d * m.z > 1e-20 && d.is_finite() {
            d
        } else {
            0.0
        }
    }

    /// The density of [`Self::sample`]'s normals: D(m) cos(m).
    #[inline]
    pub fn pdf(&self, m: glam::Vec3) -> f32 {
        if m.z < 0.0 {
            0.0
        } else {
            m.z * self.d(m)
        }
    }

    /// A normal with density D(m) cos(m) (Burley 2012, appendix B).
    pub fn sample(&self, u: glam::Vec2) -> glam::Vec3 {
        let a2 = self.alpha * self.alpha;
        let cos2 = (1.0 - a2.powf(1.0 - u.y)) / (1.0 - a2);
        let (sin, cos) = ((1.0 - cos2).max(0.0).sqrt(), cos2.max(0.0).sqrt());
        let phi = 2.0 * PI * u.x;
        glam::Vec3::new(phi.cos() * sin, phi.sin() * sin, cos)
    }
}

/// Smith's masking of the clearcoat, GGX of alpha 0.25 (Mitsuba's
/// `smith_ggx1`): zero where `v` sees the microfacet's back.
#[inline]
pub fn clearcoat_g1(v: glam::Vec3, m: glam::Vec3) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    let c2 = v.z * v.z;
    if c2 >= 1.0 {
        return 1.0;
    }
    let tan2 = (1.0 - c2) / c2;
    2.0 / (1.0 + (1.0 + 0.0625 * tan2).sqrt())
}

/// The diffuse lobe's shape, times base / pi: Lambert weighted by
/// (1 - F_o / 2)(1 - F_i / 2) with Schlick's weights, plus Burley's
/// retro-reflection R (F_o + F_i + F_o F_i (R - 1)), R = 2 roughness
/// cos_d^2, blended by `flatness` with the fake subsurface
/// 1.25 (F_ss (1 / (cos_o + cos_i) - 0.5) + 0.5) (Hanrahan–Krueger's
/// shape), for `cos_o`, `cos_i` > 0 and the half-angle cosine `cos_d`.
#[inline]
pub fn diffuse_shape(cos_o: f32, cos_i: f32, cos_d: f32, roughness: f32, flatness: f32) -> f32 {
    let (fo, fi) = (schlick_weight(cos_o), schlick_weight(cos_i));
    let lambert = (1.0 - 0.5 * fo) * (1.0 - 0.5 * fi);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let retro = rr * (fo + fi + fo * fi * (rr - 1.0));
    if flatness == 0.0 {
        return lambert + retro;
    }
    let fss90 = 0.5 * rr;
    let fss = (1.0 + (fss90 - 1.0) * fo) * (1.0 + (fss90 - 1.0) * fi);
    let ss = 1.25 * (fss * (1.0 / (cos_o + cos_i) - 0.5) + 0.5);
    (lambert + retro) * (1.0 - flatness) + ss * flatness
}

/// The integral of [`diffuse_shape`] times cos_i / pi over the hemisphere
/// of `wi`, for `wo` at `cos_o`: what the diffuse lobe reflects towards
/// `wo` of light arriving evenly, over base. Closed form without
/// flatness (cos_d^2 = (1 + wo . wi) / 2; the moments of (1 - mu)^5 are
/// Beta functions: E[F] = 1/21, E[mu F] = 1/84, E[mu^2 F] = 1/252 under
/// the cosine-weighted average), a fixed quadrature of the fake
/// subsurface's share with it.
pub fn diffuse_albedo(cos_o: f32, roughness: f32, flatness: f32) -> f32 {
    let a = schlick_weight(cos_o);
    let r = roughness;
    let (e_f, e_mu_f, e_mu2_f) = (1.0 / 21.0, 1.0 / 84.0, 1.0 / 252.0);
    let lambert = (1.0 - 0.5 * a) * (1.0 - 0.5 * e_f);
    // R = r (1 + wo . wi); E[wo . wi] = cos_o E[mu] = 2 cos_o / 3.
    let e_r = r * (1.0 + 2.0 * cos_o / 3.0);
    let e_r_f = r * (e_f + cos_o * e_mu_f);
    // (wo . wi)^2 averaged over azimuth: cos_o^2 mu^2 + sin_o^2 (1 - mu^2) / 2.
    let e_dot2_f = cos_o * cos_o * e_mu2_f + 0.5 * (1.0 - cos_o * cos_o) * (e_f - e_mu2_f);
    let e_r2_f = r * r * (e_f + 2.0 * cos_o * e_mu_f + e_dot2_f);
    let retro = a * e_r + (1.0 - a) * e_r_f + a * e_r2_f;
    let smooth = lambert + retro;
    if flatness == 0.0 {
        return smooth;
    }
    let full = quadrature(cos_o, |ci, cd| diffuse_shape(cos_o, ci, cd, roughness, 1.0));
    smooth * (1.0 - flatness) + full * flatness
}

/// The integral of Schlick's weight of the half-angle cosine times
/// cos_i / pi over the hemisphere, for `wo` at `cos_o`: the sheen's albedo
/// over its colour (tabulated once over cos_o, linearly interpolated).
pub fn sheen_albedo(cos_o: f32) -> f32 {
    const N: usize = 33;
    static TABLE: OnceLock<[f32; N]> = OnceLock::new();
    let t = TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let c = (i as f32 / (N - 1) as f32).max(1e-4);
            quadrature(c, |_, cd| schlick_weight(cd))
        })
    });
    let x = cos_o.clamp(0.0, 1.0) * (N - 1) as f32;
    let i = (x as usize).min(N - 2);
    t[i] + (t[i + 1] - t[i]) * (x - i as f32)
}

/// The cosine-weighted mean over the hemisphere of `f(cos_i, cos_d)`, for
/// `wo` at `cos_o` in the xz plane: a midpoint rule in t = sqrt(cos_i)
/// (dense at grazing, where the fake subsurface's 1 / (cos_o + cos_i)
/// peaks) and in the azimuth over [0, pi] (the integrand is even in it).
/// Deterministic; within 0.5% for these shapes.
fn quadrature(cos_o: f32, f: impl Fn(f32, f32) -> f32) -> f32 {
    const NT: usize = 48;
    const NP: usize = 24;
    let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
    let mut sum = 0.0f64;
    for i in 0..NT {
        let t = (i as f32 + 0.5) / NT as f32;
        let mu = t * t;
        let sin_i = (1.0 - mu * mu).max(0.0).sqrt();
        let mut ring = 0.0f64;
        for j in 0..NP {
            let phi = std::f32::consts::PI * (j as f32 + 0.5) / NP as f32;
            let dot = cos_o * mu + sin_o * sin_i * phi.cos();
            let cos_d = (0.5 * (1.0 + dot)).max(0.0).sqrt();
            ring += f(mu.max(1e-6), cos_d) as f64;
        }
        // E[g] = integral of g 4 t^3 dt (the cosine weight mu dmu / pi, mu = t^2).
        sum += ring * 4.0 * (t as f64).powi(3);
    }
    (sum / (NT * NP) as f64) as f32
}

/// Mitsuba's sampling rates of a principled BSDF's lobes (they change how
/// its directions are drawn, not the image). A material holds an index
/// into a table of the few distinct sets a process meets, so that it
/// stays a small `Copy` value: index 0 is every rate 1, Mitsuba's default.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Rates(u8);

/// Up to this many distinct sets of sampling rates in a process.
const MAX_RATES: usize = 256;

static RATES: [OnceLock<[f32; 4]>; MAX_RATES] = [const { OnceLock::new() }; MAX_RATES];
static RATES_LOCK: Mutex<usize> = Mutex::new(1);

impl Rates {
    /// The rates' index, interned; `None` past [`MAX_RATES`] distinct
    /// sets (a scene reader refuses them).
    pub fn intern(rates: [f32; 4]) -> Option<Rates> {
        if rates == [1.0; 4] {
            return Some(Rates(0));
        }
        let mut count = RATES_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = (1..*count).find(|&i| RATES[i].get() == Some(&rates)) {
            return Some(Rates(i as u8));
        }
        if *count >= MAX_RATES {
            return None;
        }
        let i = *count;
        let _ = RATES[i].set(rates);
        *count += 1;
        Some(Rates(i as u8))
    }

    /// The four rates (1 each for an index never interned).
    #[inline]
    pub fn get(self) -> [f32; 4] {
        match self.0 {
            0 => [1.0; 4],
            i => RATES[i as usize].get().copied().unwrap_or([1.0; 4]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};

    /// The closed-form albedo against a Monte Carlo integral of the shape,
    /// over roughness and incidence (flatness 0 and 1).
    #[test]
    fn the_diffuse_albedo_is_the_shape_integrated() {
        let mut rng = stream(4, Domain::Camera, 0);
        for (r, flat) in [(0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (0.3, 1.0), (0.8, 0.5)] {
            for cos_o in [0.05f32, 0.4, 0.9, 1.0] {
                let wo = glam::Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let n = 400_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let wi = uniform_cone(next_2d(&mut rng), 0.0);
                    let cos_d = (0.5 * (1.0 + wo.dot(wi))).sqrt();
                    sum += (diffuse_shape(cos_o, wi.z, cos_d, r, flat) * wi.z * 2.0) as f64;
                }
                let mc = (sum / n as f64) as f32;
                let closed = diffuse_albedo(cos_o, r, flat);
                assert!(
                    (mc - closed).abs() < 0.01 * closed.max(0.1),
                    "r {r} flat {flat} cos {cos_o}: {mc} vs {closed}"
                );
            }
        }
    }

    #[test]
    fn gtr1_is_normalised_and_schlick_meets_its_ends() {
        let d = Gtr1::from_gloss(0.3);
        let mut rng = stream(5, Domain::Camera, 0);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let m = uniform_cone(next_2d(&mut rng), 0.0);
            sum += (d.pdf(m) * 2.0 * PI) as f64;
        }
        assert!((sum / n as f64 - 1.0).abs() < 0.03, "{}", sum / n as f64);
        let r0 = Color::splat(0.04);
        assert!((schlick(r0, 1.0, 1.5).x - 0.04).abs() < 1e-6);
        assert!((schlick(r0, 0.0, 1.5).x - 1.0).abs() < 1e-6);
        // Out of the denser side past the critical angle: all reflected.
        assert!((schlick(r0, 0.3, 1.0 / 1.5).x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn rates_intern_to_the_same_index() {
        let a = Rates::intern([0.5, 1.0, 2.0, 1.0]).unwrap();
        assert_eq!(Rates::intern([0.5, 1.0, 2.0, 1.0]), Some(a));
        assert_eq!(a.get(), [0.5, 1.0, 2.0, 1.0]);
        assert_eq!(Rates::intern([1.0; 4]), Some(Rates::default()));
    }
}
