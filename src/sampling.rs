//! Warps from the unit square to the shapes the renderer samples, each next
//! to its pdf so the two cannot drift apart; and the random streams, keyed by
//! work-item indices (pixel, photon) and never by thread, so an image does not
//! depend on how rayon schedules work.

use glam::{Vec2, Vec3};
use rand::RngExt;
use rand_pcg::Pcg32;
use std::f32::consts::{FRAC_PI_4, PI};

/// The generator every stream uses (named, so its algorithm cannot change
/// under us the way `SmallRng`'s may).
pub type Rng = Pcg32;

/// SplitMix64 finaliser: decorrelates sequential indices before they seed PCG.
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Domains keep the camera pass, the global photon pass and the caustic photon
/// pass on disjoint streams even when their indices coincide.
#[derive(Clone, Copy, Debug)]
#[repr(u64)]
pub enum Domain {
    Camera = 0x00C4_3E8A,
    GlobalPhotons = 0x0061_0B41,
    CausticPhotons = 0x00CA_05C1,
    EdgeProbes = 0x00ED_6E00,
    CacheDirect = 0x00CA_D1EC,
    EmissionPilot = 0x00E1_9170,
    MediumPilot = 0x0011_7CE1,
}

/// The random stream of work item `index` in `domain` for run `seed`.
pub fn stream(seed: u64, domain: Domain, index: u64) -> Rng {
    let state = splitmix64(seed ^ splitmix64(domain as u64));
    Pcg32::new(state, splitmix64(index))
}

/// A uniform sample in [0, 1)^2.
pub fn next_2d(rng: &mut Rng) -> Vec2 {
    Vec2::new(rng.random::<f32>(), rng.random::<f32>())
}

/// Shirley–Chiu concentric map: uniform on the unit disk, preserves strata.
/// pdf with respect to area: 1 / pi.
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // The angle is pi/4 times a ratio in [-1, 1], measured from the x axis
    // (or, with sine and cosine swapped, from the y axis), so sine and
    // cosine are needed only on [-pi/4, pi/4], where short polynomials
    // reach f32 precision without the library's range reduction.
    // Which axis is chosen is a coin toss from sample to sample, and as a
    // branch it was mispredicted half the time: chosen with bit masks.
    let by_y = o.x.abs() <= o.y.abs();
    let (num, den) = (pick(by_y, o.x, o.y), pick(by_y, o.y, o.x));
    let (s, c) = sin_cos_quarter(FRAC_PI_4 * (num / den));
    den * Vec2::new(pick(by_y, s, c), pick(by_y, c, s))
}

/// `if yes { a } else { b }` without a branch.
#[inline(always)]
fn pick(yes: bool, a: f32, b: f32) -> f32 {
    let mask = 0u32.wrapping_sub(yes as u32);
    f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// (sin t, cos t) for |t| <= pi/4, within 2e-7 of the exact values:
/// Cephes' minimax polynomials for `sinf` / `cosf` on that interval.
#[inline]
fn sin_cos_quarter(t: f32) -> (f32, f32) {
    let z = t * t;
    let s = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * t + t;
    let c = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    (s, c)
}

/// Cosine-weighted direction on the hemisphere around local +z (Malley).
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// pdf of [`cosine_hemisphere`] per unit solid angle, for local direction `w`.
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    w.z.max(0.0) / PI
}

/// Uniform direction inside the cone around local +z with half-angle
/// `acos(cos_max)`; `cos_max` in [-1, 1), -1 being the whole sphere.
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u.x * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// pdf of [`uniform_cone`] per unit solid angle (inside the cone).
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// Axis and cosine of the half-angle of the cone from `from` that just
/// contains the sphere (`center`, `radius`); the whole sphere of
/// directions (cosine -1) from inside it.
pub fn cone_to_sphere(from: Vec3, center: Vec3, radius: f32) -> (Vec3, f32) {
    let d = center - from;
    let dist2 = d.length_squared();
    if dist2 <= radius * radius || dist2 == 0.0 {
        return (Vec3::Z, -1.0);
    }
    let sin2 = radius * radius / dist2;
    (d / dist2.sqrt(), (1.0 - sin2).max(0.0).sqrt())
}

/// Uniform point on a triangle as barycentrics (b1, b2) of v1 and v2
/// (pdf 1 / area); the square-root warp (Shirley & Chiu).
pub fn uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(su * (1.0 - u.y), su * u.y)
}

/// `n` rays from uniform points in the box [`lo`, `hi`] in uniform
/// directions, from the camera-domain stream `seed`: the incoherent rays of
/// the ray-casting benches.
pub fn random_rays(lo: Vec3, hi: Vec3, n: usize, seed: u64) -> Vec<crate::math::Ray> {
    let mut rng = stream(seed, Domain::Camera, 0);
    (0..n)
        .map(|_| {
            let (a, b) = (next_2d(&mut rng), next_2d(&mut rng));
            let o = lo + (hi - lo) * Vec3::new(a.x, a.y, b.x);
            crate::math::Ray::new(o, uniform_cone(next_2d(&mut rng), -1.0))
        })
        .collect()
}

/// The `index`-th of `n` jittered strata of [0,1)^2 (an `m x m` grid when `n`
/// is a square; otherwise `n` strata along a line, still jittered).
pub fn stratified_2d(index: u32, n: u32, u: Vec2) -> Vec2 {
    let m = (n as f32).sqrt() as u32;
    if m * m == n {
        let (ix, iy) = (index % m, index / m);
        Vec2::new((ix as f32 + u.x) / m as f32, (iy as f32 + u.y) / m as f32)
    } else {
        Vec2::new((index as f32 + u.x) / n as f32, u.y)
    }
    .min(Vec2::splat(1.0 - f32::EPSILON * 0.5))
}

/// Point `index` of the two-dimensional Sobol sequence, Owen-scrambled
/// by `scramble` (hash-based nested uniform scrambling, Burley 2020).
/// Each point is uniform on [0,1)^2, and the 2^m points from any multiple
/// of 2^m lie one in each cell of every grid of 2^a x 2^b cells with
/// a + b = m: a pixel's samples stay stratified across the passes of a
/// progressive render, where independent passes would each add a uniform
/// point (the sharp edge of a sunlit patch converges as N^-1.5 in
/// variance, not N^-1).
pub fn sobol_owen_2d(index: u32, scramble: u64) -> Vec2 {
    owen_2d(sobol_2d_bits(index), scramble)
}

/// The bits of point `index` of the unscrambled two-dimensional Sobol
/// sequence. They are linear in the index's bits: the point of `a ^ b`
/// is the XOR of the points of `a` and `b`, so the points of a block
/// `base ^ g` (`g` below the block's aligned size) are the base's bits
/// XOR small `g`'s, computed once for the block.
pub fn sobol_2d_bits(index: u32) -> [u32; 2] {
    let x = index.reverse_bits();
    let mut y = 0u32;
    let (mut i, mut v) = (index, 1u32 << 31);
    while i != 0 {
        if i & 1 == 1 {
            y ^= v;
        }
        i >>= 1;
        v ^= v >> 1;
    }
    [x, y]
}

/// Sobol bits ([`sobol_2d_bits`]) Owen-scrambled by `scramble`, as a point
/// of [0,1)^2.
pub fn owen_2d([x, y]: [u32; 2], scramble: u64) -> Vec2 {
    let unit = |bits: u32| (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32);
    Vec2::new(unit(owen_scramble(x, scramble as u32)), unit(owen_scramble(y, (scramble >> 32) as u32)))
}

/// Two points of [0,1)^2 for photon `index` of the pass whose streams
/// `seed` keys: the first four dimensions of the Sobol sequence, each
/// Owen-scrambled (Burley 2020), as (dimensions 0 and 3, dimensions 1
/// and 2). Each point on its own is uniform, and the first photons of a
/// pass fill the four-dimensional cube evenly: a light's caustic photons
/// read through them cover its directions and the aimed disk jointly
/// stratified (the photons of a sun, a part of the map's directions, still
/// cover the disk evenly), where random ones leave the Poisson noise of
/// where they happen to fall. Every 2^32 photons take scrambles of their
/// own.
pub fn photon_points(seed: u64, index: u64) -> [Vec2; 2] {
    let key = splitmix64(seed ^ splitmix64(QUASI_PHOTONS ^ (index >> 32)));
    let x = sobol_4d(index as u32);
    let unit = |d: usize| {
        let scramble = splitmix64(key.wrapping_add(d as u64)) as u32;
        (owen_scramble(x[d], scramble) >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    };
    [Vec2::new(unit(0), unit(3)), Vec2::new(unit(1), unit(2))]
}

/// Keys [`photon_points`]' scrambles apart from every [`Domain`]'s streams.
const QUASI_PHOTONS: u64 = 0x0051_0B01;

/// The generator matrices of the Sobol sequence's first four dimensions,
/// as 32 direction numbers each (bit 31 the coarsest): the van der Corput
/// sequence, then the primitive polynomials x + 1, x^2 + x + 1 and
/// x^3 + x + 1 with initial numbers 1; 1, 3; 1, 3, 1 (Joe & Kuo 2008,
/// "Constructing Sobol sequences with better two-dimensional
/// projections", their table's first rows), extended by Bratley & Fox's
/// recurrence m_k = 2 a_1 m_{k-1} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}.
const SOBOL_4D: [[u32; 32]; 4] = {
    // (degree s, the polynomial's inner coefficients a_1 .. a_{s-1} as
    // bits, a_1 highest; the initial m_1 .. m_s).
    const POLYS: [(usize, u32, [u32; 3]); 3] = [(1, 0, [1, 0, 0]), (2, 1, [1, 3, 0]), (3, 1, [1, 3, 1])];
    let mut v = [[0u32; 32]; 4];
    let mut k = 0;
    while k < 32 {
        v[0][k] = 1 << (31 - k);
        k += 1;
    }
    let mut d = 0;
    while d < 3 {
        let (s, a, init) = POLYS[d];
        let mut m = [0u64; 32];
        let mut k = 0;
        while k < 32 {
            m[k] = if k < s {
                init[k] as u64
            } else {
                let mut x = m[k - s] ^ (m[k - s] << s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        x ^= m[k - j] << j;
                    }
                    j += 1;
                }
                x
            };
            v[d + 1][k] = (m[k] << (31 - k)) as u32;
            k += 1;
        }
        d += 1;
    }
    v
};

/// Point `index` of the Sobol sequence's first four dimensions, unscrambled,
/// as 32-bit fractions.
fn sobol_4d(index: u32) -> [u32; 4] {
    let mut x = [0u32; 4];
    let (mut i, mut k) = (index, 0);
    while i != 0 {
        if i & 1 == 1 {
            for (xd, v) in x.iter_mut().zip(&SOBOL_4D) {
                *xd ^= v[k];
            }
        }
        i >>= 1;
        k += 1;
    }
    x
}

/// `index` shuffled by nested uniform scrambling of its bits (Burley 2020,
/// "Practical Hash-based Owen Scrambling", JCGT 9(4), section 4): each
/// aligned block of 2^m indices goes to an aligned block of 2^m, so a
/// sequence read through the shuffle keeps its strata, and its points are
/// paired at random with those of a sequence read in order (a pixel's lens
/// points with its positions on the film).
pub fn shuffled_index(index: u32, seed: u32) -> u32 {
    owen_scramble(index, seed)
}

/// Nested uniform scrambling of the bits of `x` (each bit flipped by a
/// hash of the bits above it): the Laine–Karras permutation on the
/// reversed bits.
fn owen_scramble(x: u32, seed: u32) -> u32 {
    let mut x = x.reverse_bits().wrapping_add(seed);
    for k in [0x6c50_b47c_u32, 0xb82f_1e52, 0xc7af_e638, 0x8d22_f6e6] {
        x ^= x.wrapping_mul(k);
    }
    x.reverse_bits()
}

/// A distribution over `0..n` in proportion to non-negative weights,
/// drawn by inverting its cumulative shares: the lights by power, a bright
/// spot's cells by irradiance.
#[derive(Clone, Debug, PartialEq)]
pub struct Discrete {
    /// Cumulative shares; the last is 1.
    cdf: Vec<f32>,
}

impl Discrete {
    /// None where the weights (a negative or non-finite one counting as
    /// zero) sum to zero.
    pub fn new(weights: impl IntoIterator<Item = f64>) -> Option<Self> {
        let weights: Vec<f64> = weights.into_iter().map(|w| if w.is_finite() && w > 0.0 { w } else { 0.0 }).collect();
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut running = 0.0;
        let mut cdf: Vec<f32> = weights
            .iter()
            .map(|w| {
                running += w;
                (running / total) as f32
            })
            .collect();
        *cdf.last_mut()? = 1.0;
        Some(Discrete { cdf })
    }

    /// The index `u` in [0, 1) draws, and `u` stretched to [0, 1] over
    /// that index's share (a second uniform number for free).
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let i = self.cdf.partition_point(|&c| c <= u).min(self.cdf.len() - 1);
        let (lo, width) = (self.below(i), self.prob(i));
        let rest = if width > 0.0 { ((u - lo) / width).clamp(0.0, 1.0) } else { 0.5 };
        (i, rest)
    }

    /// The probability that [`Self::sample`] draws `i`: a share below
    /// f32's resolution is never drawn, and has probability zero.
    pub fn prob(&self, i: usize) -> f32 {
        self.cdf[i] - self.below(i)
    }

    fn below(&self, i: usize) -> f32 {
        if i == 0 {
            0.0
        } else {
            self.cdf[i - 1]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unscrambled generator gives Joe & Kuo's first points (in index
    /// order, not their Gray-code order).
    #[test]
    fn the_four_dimensional_sobol_points_are_joe_and_kuos() {
        let f = |x: [u32; 4]| x.map(|v| v as f64 / 4_294_967_296.0);
        assert_eq!(f(sobol_4d(0)), [0.0; 4]);
        assert_eq!(f(sobol_4d(1)), [0.5; 4]);
        assert_eq!(f(sobol_4d(2)), [0.25, 0.75, 0.75, 0.75]);
        assert_eq!(f(sobol_4d(3)), [0.75, 0.25, 0.25, 0.25]);
        assert_eq!(f(sobol_4d(4)), [0.125, 0.625, 0.375, 0.125]);
        assert_eq!(f(sobol_4d(6)), [0.375, 0.375, 0.625, 0.875]);
    }

    /// A photon's points, for any pass's seed and block of 2^m photons
    /// from a multiple of 2^m: in four dimensions every box of volume
    /// 2^(3-m) (2^-a0 x 2^-a1 x 2^-a2 x 2^-a3, a0 + .. + a3 = m - 3) holds
    /// 8 of them (a (3, m, 4)-net: the Sobol sequence's t for these
    /// polynomials, 0 + 0 + 1 + 2), the aimed disk's point with the
    /// direction's first coordinate every box of volume 2^(1-m) holds 2,
    /// and each point alone lies in [0, 1)^2.
    #[test]
    fn photon_points_are_a_four_dimensional_net() {
        fn boxes(parts: usize, total: u32, f: &mut dyn FnMut(&[u32])) {
            fn go(a: &mut Vec<u32>, parts: usize, left: u32, f: &mut dyn FnMut(&[u32])) {
                if a.len() + 1 == parts {
                    a.push(left);
                    f(a);
                    a.pop();
                    return;
                }
                for x in 0..=left {
                    a.push(x);
                    go(a, parts, left - x, f);
                    a.pop();
                }
            }
            go(&mut Vec::new(), parts, total, f);
        }
        for seed in [0u64, 7, u64::MAX] {
            for m in 3..=9u32 {
                let n = 1u64 << m;
                for block in [0u64, 3] {
                    let pts: Vec<[f32; 4]> = (0..n)
                        .map(|i| {
                            let [a, b] = photon_points(seed, block * n + i);
                            for p in [a, b] {
                                assert!(p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all(), "{p}");
                            }
                            [a.x, b.x, b.y, a.y]
                        })
                        .collect();
                    for (dims, t) in [(&[0usize, 1, 2, 3][..], 3u32), (&[0, 1, 2][..], 1)] {
                        boxes(dims.len(), m - t, &mut |a| {
                            let mut count = std::collections::HashMap::new();
                            for p in &pts {
                                let key: Vec<u32> =
                                    dims.iter().zip(a).map(|(&d, &ad)| (p[d] * (1u32 << ad) as f32) as u32).collect();
                                *count.entry(key).or_insert(0u32) += 1;
                            }
                            assert!(count.values().all(|&c| c == 1 << t), "seed {seed} m {m} dims {dims:?} {a:?}");
                        });
                    }
                }
            }
        }
    }

    /// Every block of 2^m consecutive points from a multiple of 2^m holds
    /// one point in each cell of every 2^a x 2^b grid (a + b = m), for any
    /// scramble; and a point's position over scrambles is uniform.
    #[test]
    fn scrambled_sobol_points_are_stratified_in_every_block_and_uniform() {
        for scramble in [0u64, 1, 0xdead_beef_0123_4567, u64::MAX] {
            for m in 0..=6u32 {
                let n = 1u32 << m;
                for block in [0u32, 1, 5] {
                    let points: Vec<Vec2> = (0..n).map(|i| sobol_owen_2d(block * n + i, scramble)).collect();
                    for a in 0..=m {
                        let (cx, cy) = (1u32 << a, 1u32 << (m - a));
                        let mut seen = vec![false; n as usize];
                        for p in &points {
                            assert!(p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all(), "{p}");
                            let cell = (p.x * cx as f32) as u32 + cx * (p.y * cy as f32) as u32;
                            assert!(!std::mem::replace(&mut seen[cell as usize], true), "m {m} a {a} block {block}");
                        }
                    }
                }
            }
        }
        // Index 5 over many scrambles: each of 16 cells gets its share.
        let draws = 64_000;
        let mut cells = [0u32; 16];
        for k in 0..draws {
            let p = sobol_owen_2d(5, splitmix64(k));
            cells[(p.x * 4.0) as usize + 4 * (p.y * 4.0) as usize] += 1;
        }
        let share = draws as f64 / 16.0;
        for c in cells {
            assert!((c as f64 - share).abs() < 5.0 * share.sqrt(), "{cells:?}");
        }
    }

    #[test]
    fn quarter_sine_and_cosine_are_accurate() {
        let n = 1_000_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let t = (i as f32 / n as f32 * 2.0 - 1.0) * FRAC_PI_4;
            let (s, c) = sin_cos_quarter(t);
            let (es, ec) = (t as f64).sin_cos();
            worst = worst.max((s as f64 - es).abs()).max((c as f64 - ec).abs());
        }
        assert!(worst < 2e-7, "worst error {worst:e}");
    }

    #[test]
    fn concentric_disk_matches_the_trigonometric_map() {
        // The map as Shirley and Chiu wrote it, with the library's sine and cosine.
        let reference = |u: Vec2| {
            let o = 2.0 * u - Vec2::ONE;
            let (r, theta) = if o.x.abs() > o.y.abs() {
                (o.x as f64, std::f64::consts::FRAC_PI_4 * (o.y as f64 / o.x as f64))
            } else {
                (o.y as f64, std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (o.x as f64 / o.y as f64))
            };
            (r * theta.cos(), r * theta.sin())
        };
        let n = 700;
        for i in 0..=n {
            for j in 0..=n {
                let u = Vec2::new(i as f32 / n as f32, j as f32 / n as f32);
                if u == Vec2::splat(0.5) {
                    continue;
                }
                let d = concentric_disk(u);
                let (x, y) = reference(u);
                assert!((d.x as f64 - x).abs() < 4e-7 && (d.y as f64 - y).abs() < 4e-7, "{u}: {d} vs ({x}, {y})");
            }
        }
        assert_eq!(concentric_disk(Vec2::splat(0.5)), Vec2::ZERO);
    }

    /// Pearson's chi-square statistic of `counts` against equal expectation.
    fn chi_square(counts: &[u32]) -> f64 {
        let total: u32 = counts.iter().sum();
        let expected = total as f64 / counts.len() as f64;
        counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum()
    }

    /// 99 degrees of freedom: the 0.999 quantile is 148.2. A correct warp
    /// fails this once in a thousand seeds; a wrong one (e.g. uniform instead
    /// of cosine) scores in the thousands.
    const CHI2_99_P999: f64 = 148.2;

    /// Cosine-weighted directions have z^2 and phi uniform in [0, 1) x [0, 2pi).
    fn cosine_histogram(warp: impl Fn(Vec2) -> Vec3) -> Vec<u32> {
        let mut rng = stream(2024, Domain::Camera, 1);
        let mut counts = vec![0u32; 100];
        for _ in 0..200_000 {
            let w = warp(next_2d(&mut rng));
            let a = ((w.z * w.z) * 10.0).min(9.999) as usize;
            let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI) / (2.0 * PI);
            let b = (phi * 10.0).min(9.999) as usize;
            counts[a * 10 + b] += 1;
        }
        counts
    }

    #[test]
    fn cosine_hemisphere_passes_chi_square() {
        let chi2 = chi_square(&cosine_histogram(cosine_hemisphere));
        assert!(chi2 < CHI2_99_P999, "chi2 = {chi2}");
        // The test has power: a uniform hemisphere warp fails it.
        let uniform = cosine_histogram(|u| uniform_cone(u, 0.0));
        assert!(chi_square(&uniform) > 10.0 * CHI2_99_P999);
    }

    #[test]
    fn cosine_pdf_integrates_to_one() {
        // Midpoint rule over the hemisphere in (cos theta, phi).
        let n = 400;
        let mut sum = 0.0f64;
        for i in 0..n {
            let z = (i as f32 + 0.5) / n as f32;
            let w = Vec3::new((1.0 - z * z).sqrt(), 0.0, z);
            sum += cosine_hemisphere_pdf(w) as f64 * (2.0 * std::f64::consts::PI) / n as f64;
        }
        assert!((sum - 1.0).abs() < 1e-4, "{sum}");
        assert_eq!(cosine_hemisphere_pdf(Vec3::new(0.0, 0.0, -1.0)), 0.0);
    }

    #[test]
    fn uniform_cone_passes_chi_square() {
        // Uniform in the cone: cos theta uniform in [cos_max, 1], phi uniform.
        let cos_max = 0.7f32;
        let mut rng = stream(77, Domain::Camera, 2);
        let mut counts = vec![0u32; 100];
        for _ in 0..200_000 {
            let w = uniform_cone(next_2d(&mut rng), cos_max);
            assert!(w.z >= cos_max - 1e-6 && (w.length() - 1.0).abs() < 1e-5);
            let a = (((w.z - cos_max) / (1.0 - cos_max)) * 10.0).clamp(0.0, 9.999) as usize;
            let b = ((w.y.atan2(w.x).rem_euclid(2.0 * PI) / (2.0 * PI)) * 10.0).min(9.999) as usize;
            counts[a * 10 + b] += 1;
        }
        let chi2 = chi_square(&counts);
        assert!(chi2 < CHI2_99_P999, "chi2 = {chi2}");
        assert!((uniform_cone_pdf(cos_max) - 1.0 / (2.0 * PI * 0.3)).abs() < 1e-6);
    }

    #[test]
    fn concentric_disk_is_uniform_by_area() {
        // Uniform by area: r^2 and phi uniform.
        let mut rng = stream(5, Domain::Camera, 3);
        let mut counts = vec![0u32; 100];
        for _ in 0..200_000 {
            let p = concentric_disk(next_2d(&mut rng));
            assert!(p.length() <= 1.0 + 1e-6);
            let a = (p.length_squared() * 10.0).min(9.999) as usize;
            let b = ((p.y.atan2(p.x).rem_euclid(2.0 * PI) / (2.0 * PI)) * 10.0).min(9.999) as usize;
            counts[a * 10 + b] += 1;
        }
        let chi2 = chi_square(&counts);
        assert!(chi2 < CHI2_99_P999, "chi2 = {chi2}");
    }

    #[test]
    fn streams_depend_on_index_and_domain_not_on_order() {
        let a: Vec<u32> = (0..4).map(|i| stream(1, Domain::Camera, i).random::<u32>()).collect();
        let b: Vec<u32> = (0..4).rev().map(|i| stream(1, Domain::Camera, i).random::<u32>()).rev().collect();
        assert_eq!(a, b);
        assert_ne!(a[0], a[1]);
        assert_ne!(stream(1, Domain::Camera, 0).random::<u32>(), stream(1, Domain::GlobalPhotons, 0).random::<u32>());
        assert_ne!(stream(1, Domain::Camera, 0).random::<u32>(), stream(2, Domain::Camera, 0).random::<u32>());
    }

    #[test]
    fn stratified_samples_stay_in_their_cell() {
        for n in [1u32, 4, 9, 16, 5] {
            for i in 0..n {
                let lo = stratified_2d(i, n, Vec2::ZERO);
                let hi = stratified_2d(i, n, Vec2::splat(0.999_999));
                assert!(lo.cmpge(Vec2::ZERO).all() && hi.cmplt(Vec2::ONE).all());
                assert!(hi.x - lo.x <= 1.0 / (n as f32).sqrt().floor() + 1e-5);
            }
        }
    }

    /// Draws follow the weights, zero weights are never drawn, and the
    /// stretched number is uniform within a share.
    #[test]
    fn a_discrete_distribution_draws_in_proportion_to_its_weights() {
        let d = Discrete::new([1.0, 0.0, 3.0, -2.0, f64::NAN, 4.0]).unwrap();
        assert_eq!((d.prob(1), d.prob(3), d.prob(4)), (0.0, 0.0, 0.0));
        assert!((d.prob(0) - 0.125).abs() < 1e-6 && (d.prob(5) - 0.5).abs() < 1e-6);
        let n = 80_000;
        let (mut counts, mut rest) = ([0u32; 6], 0.0f64);
        for k in 0..n {
            let (i, r) = d.sample((k as f32 + 0.5) / n as f32);
            counts[i] += 1;
            rest += r as f64;
        }
        for i in 0..6 {
            assert!((counts[i] as f32 / n as f32 - d.prob(i)).abs() < 1e-3, "{i}: {counts:?}");
        }
        assert!((rest / n as f64 - 0.5).abs() < 1e-3);
        assert!(Discrete::new([0.0, -1.0]).is_none() && Discrete::new([]).is_none());
    }

    /// The shuffle keeps aligned blocks together (a pass's samples stay one
    /// stratum set), and pairs two sequences' points so that their joint
    /// cells fill evenly: read in order, both would put their k-th points in
    /// the same column, filling only the diagonal of a grid.
    #[test]
    fn a_shuffled_index_keeps_blocks_and_decorrelates() {
        for m in [2u32, 4, 7] {
            for block in [0u32, 1, 5, 1000] {
                let mut got: Vec<u32> = (0..1 << m).map(|i| shuffled_index((block << m) + i, 0x5EED_1234)).collect();
                let first = got[0] >> m;
                assert!(got.iter().all(|&g| g >> m == first), "m {m} block {block}: {got:?}");
                got.sort_unstable();
                got.dedup();
                assert_eq!(got.len(), 1 << m);
            }
        }
        // 4096 pairs (x of the sequence in order, x of the shuffled one) in
        // a 16 x 16 grid: 16 per cell if independent.
        let (a, b) = (0x1234_5678_9ABC_DEF0u64, 0x0FED_CBA9_8765_4321u64);
        let mut counts = vec![0u32; 256];
        let mut diagonal = vec![0u32; 256];
        for i in 0..4096u32 {
            let x = sobol_owen_2d(i, a).x;
            let y = sobol_owen_2d(shuffled_index(i, b as u32), b).x;
            let y_in_order = sobol_owen_2d(i, b).x;
            counts[(x * 16.0) as usize * 16 + (y * 16.0) as usize] += 1;
            diagonal[(x * 16.0) as usize * 16 + (y_in_order * 16.0) as usize] += 1;
        }
        let chi2 = chi_square(&counts);
        assert!(chi2 < 330.0, "chi2 = {chi2} (255 degrees of freedom, p = 0.001 at 330)");
        assert!(chi_square(&diagonal) > 1000.0, "in order, the two are correlated");
    }
}
