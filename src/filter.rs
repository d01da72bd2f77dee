//! Pixel reconstruction filters, by importance sampling: a pixel's value is
//! the filter-weighted average of the radiance around its centre,
//! ∫ f(x - c) L(x) dx / ∫ f, which is the expected radiance at a position
//! drawn from the density f / ∫ f about the centre. So a camera sample is
//! placed by warping its uniform point through the filter's inverse
//! distribution, with weight 1, and the pixel loop stays a box average
//! (Ernst et al. 2006, "Filter importance sampling"). Splatting weighted
//! samples into neighbouring pixels, as Mitsuba's film does, has the same
//! expected value; for the non-negative filters here the sampled form has
//! no negative weights and keeps the passes' exact sums.
//!
//! The filters are separable, f(x, y) = f(x) f(y), as Mitsuba 3 defines
//! them (its `box`, `tent` and `gaussian` plugins).

use glam::Vec2;
use std::sync::OnceLock;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Filter {
    /// The pixel's square (Mitsuba's `box`, radius 0.5).
    #[default]
    Box,
    /// 1 - |x| / radius (Mitsuba's `tent`, default radius 1).
    Tent { radius: f32 },
    /// exp(-x² / 2σ²) less its value at 4σ, cut at 4σ (Mitsuba's
    /// `gaussian`, default σ 0.5: its films' default filter).
    Gaussian { stddev: f32 },
}

impl Filter {
    /// The offset of a sample from the pixel's top-left corner, in pixels,
    /// for a point `u` uniform in the unit square.
    #[inline]
    pub fn place(&self, u: Vec2) -> Vec2 {
        match *self {
            Filter::Box => u,
            Filter::Tent { radius } => Vec2::new(0.5 + radius * tent(u.x), 0.5 + radius * tent(u.y)),
            Filter::Gaussian { stddev } => {
                let g = gaussian_table();
                Vec2::new(0.5 + stddev * g.invert(u.x), 0.5 + stddev * g.invert(u.y))
            }
        }
    }

    /// The filter's value at offset `x` from the pixel centre (one axis),
    /// unnormalised: for tests of [`Self::place`].
    pub fn eval(&self, x: f32) -> f32 {
        match *self {
            Filter::Box => (x.abs() <= 0.5) as u8 as f32,
            Filter::Tent { radius } => (1.0 - x.abs() / radius).max(0.0),
            Filter::Gaussian { stddev } => {
                let s = x / stddev;
                if s.abs() >= CUT {
                    0.0
                } else {
                    (-0.5 * s * s).exp() - (-0.5 * CUT * CUT).exp()
                }
            }
        }
    }

    /// How far from the pixel centre samples may land, in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            Filter::Box => 0.5,
            Filter::Tent { radius } => radius,
            Filter::Gaussian { stddev } => CUT * stddev,
        }
    }
}

/// The inverse of the unit tent's distribution on [-1, 1].
#[inline]
fn tent(u: f32) -> f32 {
    if u < 0.5 {
        (2.0 * u).sqrt() - 1.0
    } else {
        1.0 - (2.0 - 2.0 * u).max(0.0).sqrt()
    }
}

/// The Gaussian is cut at this many standard deviations (Mitsuba's 4).
const CUT: f32 = 4.0;

/// The inverse distribution of the cut Gaussian in units of σ, tabulated:
/// its shape does not depend on σ, so one table serves every filter.
struct InverseTable {
    /// Cumulative distribution at `N + 1` evenly spaced points of [-CUT, CUT].
    cdf: Vec<f32>,
}

const N: usize = 4096;

fn gaussian_table() -> &'static InverseTable {
    static TABLE: OnceLock<InverseTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let bias = (-0.5 * (CUT as f64).powi(2)).exp();
        let f = |s: f64| ((-0.5 * s * s).exp() - bias).max(0.0);
        let h = 2.0 * CUT as f64 / N as f64;
        let mut cdf = Vec::with_capacity(N + 1);
        let mut sum = 0.0f64;
        cdf.push(0.0);
        for i in 0..N {
            let (a, b) = (-(CUT as f64) + i as f64 * h, -(CUT as f64) + (i + 1) as f64 * h);
            // Simpson's rule per cell: the density is smooth.
            sum += h / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b));
            cdf.push(sum as f32);
        }
        let total = sum as f32;
        for c in &mut cdf {
            *c /= total;
        }
        InverseTable { cdf }
    })
}

impl InverseTable {
    /// The point below which a fraction `u` of the density lies (linear
    /// within a cell of the table).
    fn invert(&self, u: f32) -> f32 {
        let i = self.cdf.partition_point(|&c| c <= u).clamp(1, N) - 1;
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let f = if c1 > c0 { ((u - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.5 };
        let h = 2.0 * CUT / N as f32;
        -CUT + (i as f32 + f) * h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// χ² test of each filter's sample positions against the filter's own
    /// shape (integrated per bin), one axis at a time: 64 bins over the
    /// filter's support, 200,000 stratified-free uniform points.
    #[test]
    fn placed_samples_follow_the_filter() {
        let filters =
            [Filter::Box, Filter::Tent { radius: 1.0 }, Filter::Tent { radius: 1.5 }, Filter::Gaussian { stddev: 0.5 }];
        for filter in filters {
            let r = filter.radius();
            let bins = 64;
            let n = 200_000;
            let mut counts = vec![0f64; bins];
            let mut state = 0x9E3779B97F4A7C15u64;
            let mut next = || {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((state >> 40) as f32) / (1u64 << 24) as f32
            };
            for _ in 0..n {
                let p = filter.place(Vec2::new(next(), 0.5));
                let x = p.x - 0.5;
                assert!(x.abs() <= r + 1e-4, "{filter:?}: {x} outside radius {r}");
                let b = (((x + r) / (2.0 * r)) * bins as f32).floor().clamp(0.0, bins as f32 - 1.0) as usize;
                counts[b] += 1.0;
            }
            // Expected counts from the filter integrated over each bin.
            let sub = 64;
            let mut expected = vec![0f64; bins];
            for (b, e) in expected.iter_mut().enumerate() {
                for k in 0..sub {
                    let x = -r + 2.0 * r * (b as f32 + (k as f32 + 0.5) / sub as f32) / bins as f32;
                    *e += filter.eval(x) as f64;
                }
            }
            let total: f64 = expected.iter().sum();
            let mut chi2 = 0.0;
            let mut dof = 0;
            for (c, e) in counts.iter().zip(&expected) {
                let e = e / total * n as f64;
                if e >= 5.0 {
                    chi2 += (c - e).powi(2) / e;
                    dof += 1;
                } else {
                    assert!(*c <= 30.0, "{filter:?}: {c} samples where {e} expected");
                }
            }
            // Wilson–Hilferty: the 1e-4 upper quantile of χ²(dof).
            let k = dof as f64 - 1.0;
            let z = 3.719;
            let limit = k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3);
            assert!(chi2 < limit, "{filter:?}: χ² {chi2:.1} over {limit:.1} ({dof} bins)");
        }
    }

    /// A wrong shape fails the same test: samples placed as a tent are
    /// far from a Gaussian of the same support.
    #[test]
    fn the_gaussian_is_not_a_tent() {
        let g = Filter::Gaussian { stddev: 0.5 };
        let t = Filter::Tent { radius: 2.0 };
        // The share of samples within a quarter pixel of the centre.
        let share = |f: Filter| {
            (0..10_000).filter(|i| (f.place(Vec2::new((*i as f32 + 0.5) / 1e4, 0.5)).x - 0.5).abs() < 0.25).count()
        };
        let (sg, st) = (share(g), share(t));
        assert!(sg > st + 1000, "{sg} vs {st}");
    }
}
