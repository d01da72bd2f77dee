//! Mitsuba 3's `blendbsdf` of any two BSDFs, and its `mask` over any BSDF
//! (a blend of `null` and the BSDF by the opacity): f = (1 - w) f_1 +
//! w f_2 (src/bsdfs/blendbsdf.cpp, mask.cpp).
//!
//! Where a ray or photon meets a blend, the scene gives it one of the two
//! materials, the second with chance w, chosen by a hash of the hit
//! (`Scene::material_seen`; pbrt-v4's `MixMaterial` chooses the same way):
//! each estimator then runs on a plain material, and on average over the
//! hits it is the blend. Nothing is drawn from a path's random stream, so
//! scenes without blends render as before, and the choice is the same on
//! any number of threads. [`Mix`] is the blend as a whole, which the tests
//! hold that choice to.
//!
//! Photons are stored where either material has a diffuse lobe, whichever
//! is chosen there (the scene's `stores_photons`): an estimate read where
//! the diffuse one is chosen needs the whole of the light arriving
//! (notes/method.md).
//!
//! In the scene's table a blend is a [`Blend`]: what the scene asks of a
//! material as a whole (whether it stores photons, whether it has a
//! specular lobe). A ray never meets it.

use super::{Branches, Material, Scatter, Transport};
use crate::math::Color;
use crate::sampling::{splitmix64, Rng};
use glam::Vec3;
use rand::RngExt;

/// A blend as the scene summarises it (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Blend {
    /// Whether either material has a diffuse lobe, and their reflectances
    /// weighed by the blend's typical weight.
    pub diffuse: Option<Color>,
    /// Whether either material has a specular lobe or one that carries
    /// caustics (the blend's object is a caustic target).
    pub specular: bool,
}

impl Blend {
    /// The summary of `first` and `second` blended with weight `w`.
    pub fn of(w: f32, first: &Material, second: &Material) -> Self {
        let (a, b) = (first.diffuse_rho(), second.diffuse_rho());
        let rho = |m: Option<Color>| m.unwrap_or(Color::ZERO);
        Blend {
            diffuse: (a.is_some() || b.is_some()).then(|| rho(a) * (1.0 - w) + rho(b) * w),
            specular: first.has_specular_lobe() || second.has_specular_lobe(),
        }
    }
}

/// A uniform number in [0, 1) from a hit: its point, the direction of the
/// ray that met it and a salt (a blend's depth in a nest of blends), mixed
/// by SplitMix64 (Steele et al. 2014).
#[inline]
pub fn hit_random(point: Vec3, dir: Vec3, salt: u32) -> f32 {
    let [x, y, z] = point.to_array().map(f32::to_bits);
    let [a, b, c] = dir.to_array().map(f32::to_bits);
    let mut h = splitmix64(((x as u64) << 32 | y as u64) ^ salt as u64);
    h = splitmix64(h ^ ((z as u64) << 32 | a as u64));
    h = splitmix64(h ^ ((b as u64) << 32 | c as u64));
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// A blend of two materials as a whole: what choosing one at each hit
/// amounts to.
#[derive(Clone, Copy, Debug)]
pub struct Mix<'a> {
    /// The second material's share, in [0, 1].
    pub weight: f32,
    pub first: &'a Material,
    pub second: &'a Material,
}

impl<'a> Mix<'a> {
    /// The material a hit of uniform number `u` shows: the second where
    /// `u` < weight (a weight of 0 is the first alone, as in Mitsuba).
    #[inline]
    pub fn pick(&self, u: f32) -> &'a Material {
        if u < self.weight {
            self.second
        } else {
            self.first
        }
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3, entering: bool, mode: Transport) -> Color {
        self.first.eval(wo, wi, entering, mode) * (1.0 - self.weight)
            + self.second.eval(wo, wi, entering, mode) * self.weight
    }

    /// The density of [`Self::sample`]'s smooth directions.
    pub fn pdf(&self, wo: Vec3, wi: Vec3, entering: bool) -> f32 {
        (1.0 - self.weight) * self.first.pdf(wo, wi, entering) + self.weight * self.second.pdf(wo, wi, entering)
    }

    /// The specular branches of both, each with its material's share.
    pub fn specular_branches(&self, wo: Vec3, entering: bool, mode: Transport) -> Vec<(f32, super::Branch)> {
        let share = |m: &Material, s: f32| {
            let b: Branches = m.specular_branches(wo, entering, mode);
            b.iter().map(move |b| (s * b.prob, *b)).collect::<Vec<_>>()
        };
        let mut all = share(self.first, 1.0 - self.weight);
        all.extend(share(self.second, self.weight));
        all
    }

    /// A direction from the material a uniform number picks.
    pub fn sample(&self, wo: Vec3, entering: bool, mode: Transport, rng: &mut Rng) -> Option<Scatter> {
        let u = rng.random::<f32>();
        self.pick(u).sample(wo, entering, mode, rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hash's numbers are uniform (a χ² over 64 bins of a million
    /// neighbouring hits) and differ with the salt.
    #[test]
    fn hit_numbers_are_uniform() {
        let mut bins = [0u32; 64];
        let n = 1_000_000;
        for i in 0..n {
            let p = Vec3::new(0.1 + (i % 1000) as f32 * 1e-4, 0.5, 0.25 + (i / 1000) as f32 * 1e-4);
            let u = hit_random(p, Vec3::new(0.0, -0.6, -0.8), 0);
            assert!((0.0..1.0).contains(&u));
            bins[(u * 64.0) as usize] += 1;
        }
        let e = n as f64 / 64.0;
        let chi2: f64 = bins.iter().map(|&o| (o as f64 - e).powi(2) / e).sum();
        // 63 degrees of freedom: the 0.1% tail starts near 103.
        assert!(chi2 < 103.0, "{chi2}");
        let p = Vec3::new(0.3, 0.2, 0.1);
        assert_ne!(hit_random(p, Vec3::Z, 0), hit_random(p, Vec3::Z, 1));
    }
}
