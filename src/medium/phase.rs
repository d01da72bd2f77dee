//! Phase functions: how a medium scatters light at a point, as a density
//! over the sphere of outgoing directions. Both are sampled exactly (the
//! sample's weight is 1), so the density is also the sampling pdf.
//!
//! Directions follow the light's travel: `dir` is the direction the light
//! was travelling before it scattered, `out` the one after. With that
//! convention the Henyey–Greenstein function of asymmetry g > 0 scatters
//! forwards (towards `dir`), as Mitsuba 3's `hg` plugin does for g > 0
//! (src/phase/hg.cpp evaluates it against the reversed incoming direction,
//! which is the same function).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

const INV_FOUR_PI: f32 = 1.0 / (4.0 * PI);

/// A phase function (Mitsuba 3's `isotropic` and `hg`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// 1 / 4π everywhere.
    Isotropic,
    /// Henyey and Greenstein (1941): p(θ) = (1 - g²) / (4π (1 + g² - 2g cos θ)^{3/2}),
    /// θ the angle between `dir` and `out`, g in (-1, 1) the mean cosine.
    HenyeyGreenstein { g: f32 },
}

impl Phase {
    /// The density of scattering from travelling along unit `dir` into
    /// unit `out`, per unit solid angle.
    #[inline]
    pub fn eval(&self, dir: Vec3, out: Vec3) -> f32 {
        match *self {
            Phase::Isotropic => INV_FOUR_PI,
            Phase::HenyeyGreenstein { g } => hg(g, dir.dot(out)),
        }
    }

    /// A direction drawn with density [`Self::eval`], and that density.
    #[inline]
    pub fn sample(&self, dir: Vec3, u: Vec2) -> (Vec3, f32) {
        let g = match *self {
            Phase::Isotropic => 0.0,
            Phase::HenyeyGreenstein { g } => g,
        };
        // The inversion of the HG cumulative distribution in cos θ
        // (Henyey and Greenstein 1941; as pbrt 4th ed. §11.3.1 writes it);
        // a uniform cosine where g is too small to divide by.
        let cos = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
            ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let frame = crate::math::Frame::from_normal(dir);
        let out = frame.to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)).normalize();
        let pdf = match *self {
            Phase::Isotropic => INV_FOUR_PI,
            Phase::HenyeyGreenstein { g } => hg(g, cos),
        };
        (out, pdf)
    }

    /// The mean cosine of the scattering angle (g; 0 for isotropic).
    pub fn mean_cosine(&self) -> f32 {
        match *self {
            Phase::Isotropic => 0.0,
            Phase::HenyeyGreenstein { g } => g,
        }
    }
}

#[inline]
fn hg(g: f32, cos: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * cos;
    INV_FOUR_PI * (1.0 - g * g) / (d * d.max(0.0).sqrt()).max(f32::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, Domain};

    /// Each phase function integrates to one over the sphere, and its mean
    /// cosine is g (midpoint rule in cos θ).
    #[test]
    fn densities_integrate_to_one_with_mean_cosine_g() {
        for phase in [Phase::Isotropic, Phase::HenyeyGreenstein { g: 0.7 }, Phase::HenyeyGreenstein { g: -0.4 }] {
            let n = 200_000;
            let (mut mass, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let s = (1.0 - c * c).sqrt();
                let p = phase.eval(Vec3::Z, Vec3::new(s as f32, 0.0, c as f32)) as f64;
                mass += p * 2.0 * std::f64::consts::PI * 2.0 / n as f64;
                mean += c * p * 2.0 * std::f64::consts::PI * 2.0 / n as f64;
            }
            assert!((mass - 1.0).abs() < 1e-3, "{phase:?}: {mass}");
            assert!((mean - phase.mean_cosine() as f64).abs() < 1e-3, "{phase:?}: {mean}");
        }
    }

    /// A sample's pdf is the function's value at it, and the samples' mean
    /// cosine with the travel direction is g.
    #[test]
    fn samples_report_their_density() {
        let mut rng = stream(4, Domain::Camera, 0);
        let dir = Vec3::new(0.3, -0.5, 0.8).normalize();
        for phase in [Phase::Isotropic, Phase::HenyeyGreenstein { g: 0.9 }, Phase::HenyeyGreenstein { g: -0.6 }] {
            let n = 200_000;
            let mut mean = 0.0f64;
            for _ in 0..n {
                let (out, pdf) = phase.sample(dir, next_2d(&mut rng));
                assert!((out.length() - 1.0).abs() < 1e-5);
                let want = phase.eval(dir, out);
                assert!((pdf - want).abs() <= 2e-3 * want, "{phase:?}: {pdf} vs {want}");
                mean += out.dot(dir) as f64;
            }
            mean /= n as f64;
            assert!((mean - phase.mean_cosine() as f64).abs() < 0.01, "{phase:?}: {mean}");
        }
    }
}
