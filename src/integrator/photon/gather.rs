//! Final gathering (light → … diffuse y → specular* → x): the camera
//! pass's gather rays from a diffuse point, cosine-distributed and aimed at
//! mirrors, glass and bright spots, followed through specular chains and
//! glossy lobes to the surfaces whose precomputed irradiance they read.

use super::*;
use crate::sampling::{owen_2d, shuffled_index, sobol_2d_bits, splitmix64};

/// The density of all of a point's gather rays together towards a
/// direction of cosine `cos`: `nc` cosine rays and `na` aimed ones, whose
/// density `aimed_pdf` gives.
pub(super) fn gather_density(cos: f32, nc: u32, na: u32, aimed_pdf: impl FnOnce() -> f32) -> f32 {
    if !(cos > 0.0) {
        return 0.0;
    }
    nc as f32 * cos / PI + if na > 0 { na as f32 * aimed_pdf() } else { 0.0 }
}

/// Where a camera sample's cosine gather rays fall in the unit square:
/// sample `index` of its pixel takes the aligned block of `2^shift`
/// points (the least power of two not below the rays' count) at its
/// place `index'` in a Sobol sequence scrambled for the pixel (Owen,
/// Burley 2020), `index'` the sample's index shuffled by blocks, so that
/// the rays' points are paired at random with the sample's place in the
/// pixel, which reads the same sequence. The samples of all passes so far
/// together take an aligned block of their multiple: the pixel's gather
/// rays stay stratified over the hemisphere across passes, where rays
/// drawn anew each pass add independent noise. Each point on its own is
/// uniform: unbiased.
pub struct GatherSequence {
    /// The unscrambled bits of the block's first point.
    base: [u32; 2],
    key: u64,
    /// The block's size less one.
    mask: u32,
    /// Where in the block ray 0 reads ([`GatherSequence::rotated`]).
    offset: u32,
    /// Where it reads where the rays are fewer than the block's points.
    left_out: u32,
}

impl GatherSequence {
    pub fn new(index: u64, scramble: u64, count: u32) -> Self {
        let key = splitmix64(scramble ^ GATHER_SEQUENCE);
        let shift = count.max(1).next_power_of_two().trailing_zeros();
        let sample = shuffled_index(index as u32, (key >> 32) as u32);
        // Past 2^32 points the sequence starts over (at 4 rays, a pixel's
        // billionth sample).
        // Where fewer rays read the block than it holds (`rotated`), the
        // point they leave out moves on once per block of as many samples,
        // through every point in a shuffled order: within each group of
        // `2^shift` samples (one pass's at the default 4 spp) the rays
        // keep the old stratification, and over groups each point is left
        // out as often as any other.
        let group = shuffled_index((index >> shift) as u32, key as u32 ^ ROTATION);
        let mask = (1 << shift) - 1;
        GatherSequence { base: sobol_2d_bits(sample.wrapping_shl(shift)), key, mask, offset: 0, left_out: group & mask }
    }

    /// The sequence for `used` rays (the first `used` of
    /// [`GatherSequence::point`]'s): where they are fewer than the block's
    /// points (cosine rays beside aimed ones, a count not a power of two),
    /// they read the block cyclically from a place that moves on once per
    /// group of samples (see `new`). Read from
    /// its start, ray `g` would always take the block's point `g`, whose
    /// leading bits are `g`'s and which the pixel's scramble maps to the
    /// same stratum of the square at every sample: the strata of the
    /// points no ray reads would never be sampled in that pixel, an error
    /// of each pixel's (unbiased only over pixels) that no number of
    /// passes averages out. Moving on, each of the block's points is left
    /// out as often as any other: each pixel's estimate converges. (From a
    /// random place at each sample, the counts per quarter varied within
    /// one pass: 10-gold-glass's default command read 4-7% worse on each
    /// of 8 seeds.)
    pub fn rotated(mut self, used: u32) -> Self {
        if used <= self.mask {
            self.offset = self.left_out;
        }
        self
    }

    /// The sequence read cyclically from a random place in its block, at
    /// any count of rays: for a second sequence that the same rays read
    /// after a first (each glossy ray's next glossy sample). Ray `g`'s
    /// point of each block falls, for a pixel, in a quarter of the square
    /// fixed by `g`: read both from the start, ray `g`'s first point and
    /// its second would pair the same quarters at every sample, and
    /// three in four of the pairs of quarters would never be drawn in
    /// that pixel. From a random place each ray's second point is paired
    /// with any of the block's points with the same chance.
    pub fn from_random_place(mut self, rng: &mut crate::sampling::Rng) -> Self {
        self.offset = rng.random::<u32>() & self.mask;
        self
    }

    /// Ray `g`'s point (`g` below the block's size).
    pub fn point(&self, g: u32) -> glam::Vec2 {
        let [x, y] = sobol_2d_bits(g.wrapping_add(self.offset) & self.mask);
        owen_2d([self.base[0] ^ x, self.base[1] ^ y], self.key)
    }
}

/// Keys the order in which [`GatherSequence::rotated`] leaves points out.
const ROTATION: u32 = 0x0F15_E7A1;

/// Keys [`GatherSequence`]'s scrambles apart from the camera sample's.
const GATHER_SEQUENCE: u64 = 0x6A7E_5EED_0000_0001;

/// The fractional part of the golden ratio: a sequence stepping by it
/// fills [0, 1) evenly at every length.
const GOLDEN_RATIO_FRACTION: f32 = 0.618_034;

impl<'a> PhotonIntegrator<'a> {
    /// Light → … diffuse y → (specular*) → x: final gathering.
    ///
    /// Each read of the cache is a cache miss (gather hits land anywhere in
    /// the scene): the reads are left for the end of the pixel's samples
    /// ([`PendingRead`]), all of their fetches under way at once. The
    /// random numbers are drawn in the same order either way.
    ///
    /// Where the point sees a mirror or glass object or a bright spot, some
    /// of the rays are aimed at them ([`super::aim`]).
    /// With `mis`, the rays also bring the direct light from infinity
    /// they meet, weighted against the shadow rays'.
    pub(super) fn indirect(
        &self,
        hit: &Hit,
        n: glam::Vec3,
        rho: Color,
        w: Color,
        mis: bool,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        let count = self.settings.gather_rays;
        if count == 0 || self.cache.is_empty() {
            return Color::ZERO;
        }
        let (cosine, aimed) = self.gather_split(hit, n, sh);
        let frame = Frame::from_normal(n);
        // Each ray, cosine or aimed, weighed by the balance heuristic:
        // f cos / (cosine p_cos + aimed p_aim), f = rho / pi, p_cos = cos / pi;
        // with cosine rays alone, 1 / count.
        let (nc, na) = (cosine as f32, aimed as f32);
        let mut sum = Color::ZERO;
        let sequence =
            sh.pixel.sequence.map(|(index, scramble)| GatherSequence::new(index, scramble, count).rotated(cosine));
        for g in 0..count {
            let dir = if g < cosine {
                let u = match &sequence {
                    Some(s) => s.point(g),
                    None => stratified_2d(g, cosine, next_2d(sh.ctx.rng)),
                };
                frame.to_world(cosine_hemisphere(u)).normalize()
            } else {
                let pick = match sh.pixel.aim_pick {
                    Some(p) => p,
                    None => sh.ctx.rng.random::<f32>(),
                };
                sh.pixel.aim_pick = Some((pick + GOLDEN_RATIO_FRACTION).fract());
                sh.thread.aims.sample(pick, next_2d(sh.ctx.rng))
            };
            let cos = dir.dot(n);
            // About a shading normal a gather ray may point into the
            // surface: it gathers nothing.
            if !(cos > 0.0) || (hit.shading_normal != hit.normal && !hit.leaves_as(-n, dir, true)) {
                continue;
            }
            let c = if aimed == 0 { 1.0 / nc } else { cos / (nc * cos + na * PI * sh.thread.aims.pdf(dir)) };
            let sample = mis.then(|| {
                let aims = &sh.thread.aims;
                let pdf = gather_density(cos, cosine, aimed, || aims.pdf(dir));
                BsdfSample { compensated: true, ..self.bsdf_sample(hit, n, pdf) }
            });
            let (ray, dep) = hit.spawn(dir);
            sum += c * self.gather(ray, dep, Lobe::Diffuse, sample, 0, None, w * rho * c, sh);
        }
        rho * sum
    }

    /// How many of the gather rays at `hit` are cosine and how many aimed
    /// (the aims prepared for it).
    pub(super) fn gather_split(&self, hit: &Hit, n: glam::Vec3, sh: &mut Shade<'_, '_, 'a>) -> (u32, u32) {
        let count = self.settings.gather_rays;
        let aims = self.settings.aimed_gather_rays.min(count.saturating_sub(1));
        let aimed = if aims > 0 && sh.thread.aims.prepare(self.aims(hit.point), hit.point, n) { aims } else { 0 };
        (count - aimed, aimed)
    }

    /// What final gathering aims at: the mirror and glass objects' bounding
    /// spheres, and the bright spots that face `x`: a flat one's irradiance
    /// over its plane, a curved one's bounding sphere (either is an
    /// unbiased choice, the weights use the pdf of what was sampled; the
    /// map follows a flat spot's light closely).
    pub(super) fn aims(&self, x: glam::Vec3) -> impl Iterator<Item = Aim<'a>> + 'a {
        let targets = self.targets.iter().map(|t| Aim::Sphere(t.center, t.radius));
        targets.chain(self.spots.iter().filter(move |s| s.faces(x)).map(|s| match &s.patch {
            Some(map) => Aim::Patch(map, s.radius),
            None => Aim::Sphere(s.center, s.radius),
        }))
    }

    /// Radiance arriving along a gather ray that left a non-specular lobe
    /// (`from`), as far as this estimator is the one to count it: followed
    /// through mirrors and glass and through glossy lobes; at every surface
    /// met, its diffuse lobe's light is read from the irradiance cache (the
    /// read left for later, with weight `w` and the path's), and its glossy
    /// lobe takes its direct light by shadow rays. Light met after mirrors
    /// or glass (a light's surface, or light from everywhere where the ray
    /// leaves the scene) counts only where the last non-specular vertex was
    /// glossy: a diffuse one's is the caustic map's. Light met straight
    /// from a non-specular vertex is its direct estimate's, but where that
    /// vertex shared its direct light with the lobe's sample (`shared`:
    /// MIS at glossy lobes, [`super::mis`]): then it counts with the
    /// sample's weight (notes/method.md).
    ///
    /// A glossy lobe that carries caustics ([`crate::material::Glossy`])
    /// stands for a specular one while the path is still a diffuse
    /// vertex's (`from` diffuse): the light it brings is the caustic map's,
    /// so it takes no shadow rays and is passed through like glass.
    ///
    /// At its first `splits` rough-glass vertices passed as glossy ones the
    /// path follows both branches about the sampled microfacet normal
    /// ([`ROUGH_SPLITS`]): the reflected one by a gather of its own, by
    /// [`REFLECTED_PATHS`] of them, each about a normal of its own, where
    /// it carries most of the light.
    ///
    /// `at`: the point of the unit square that the path's first glossy
    /// sample takes (a scrambled Sobol sequence's, stratified across the
    /// pixel's samples), in place of two random numbers.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather(
        &self,
        mut ray: Ray,
        mut dep: Departure,
        mut from: Lobe,
        mut shared: Option<BsdfSample>,
        mut splits: u32,
        mut at: Option<glam::Vec2>,
        w: Color,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        let mut weight = Color::ONE;
        // A mirror or glass vertex since the last non-specular one.
        let mut specular = false;
        let mut found = Color::ZERO;
        for _ in 0..MAX_SPECULAR_DEPTH {
            sh.ctx.counters.rays += 1;
            let Some(y) = self.scene.intersect(&ray, Some(dep)) else {
                // Light from everywhere: as a light's surface below.
                if from == Lobe::Glossy && specular {
                    found += weight * self.scene.background(ray.dir);
                } else if let Some(b) = shared {
                    found += weight * b.from_infinity(self.scene, ray.dir);
                }
                break;
            };
            weight *= self.scene.transmittance(Some(dep), y.t);
            let material = &self.scene.material_seen(&y, ray.dir);
            if from == Lobe::Glossy && specular {
                found += weight * self.scene.emitted(&y, ray.dir);
            } else if let Some(b) = shared {
                // Straight from a glossy vertex that shared its direct light.
                found += weight * b.emitted(self.scene, &y, ray.dir);
            }
            if material.is_emitter() {
                break;
            }
            let (frame, entering) = y.scattering_frame(ray.dir, material);
            let wo = frame.to_local(-ray.dir);
            if material.diffuse_rho().is_some() {
                found += self.read(y.point, frame.n, weight * material.diffuse_albedo(wo) / PI, w, sh);
            }
            let glossy = material.glossy();
            // Whether the glossy lobe here is passed like glass.
            let caustic_glossy = from == Lobe::Diffuse && glossy.is_some_and(|g| g.carries_caustics());
            // On through one of the lobes that are not read here: a specular
            // branch or the glossy lobe, chosen by what each reflects.
            let branches = material.specular_branches(wo, entering, Transport::Radiance);
            let p_specular = match glossy {
                None => 1.0,
                Some(_) if branches.is_empty() => 0.0,
                Some(g) => g.specular_share(),
            };
            // The glossy lobe's direct light, shared with its sample (MIS)
            // where the setting asks.
            let lit = glossy.filter(|_| !caustic_glossy);
            let mis = lit.filter(|_| self.settings.mis);
            if let Some(g) = lit {
                let s = &self.settings;
                let both = g.transmits();
                let direct = if mis.is_some() {
                    let bsdf = |l: glam::Vec3| {
                        let wi = frame.to_local(l);
                        let shared = g.eval(wo, wi, entering, Transport::Radiance);
                        MisBsdf { alone: Color::ZERO, shared, pdf: (1.0 - p_specular) * g.pdf(wo, wi, entering) }
                    };
                    direct_light_mis(self.scene, &y, frame.n, bsdf, s.shadow_rays, s.skip, both, None, sh.ctx)
                } else {
                    let brdf = |l: glam::Vec3| g.eval(wo, frame.to_local(l), entering, Transport::Radiance);
                    direct_light(self.scene, &y, frame.n, brdf, s.shadow_rays, s.skip, both, None, sh.ctx)
                };
                found += weight * direct;
            }
            shared = None;
            let next_dir = if p_specular >= 1.0 || (p_specular > 0.0 && sh.ctx.rng.random::<f32>() < p_specular) {
                let Some(b) = branches.choose(sh.ctx.rng) else { break };
                weight *= b.scale / p_specular;
                specular = true;
                frame.to_world(b.wi).normalize()
            } else {
                let Some(g) = glossy else { break };
                let split = splits > 0 && !caustic_glossy && g.splits();
                let [first, second] = match at.take() {
                    Some(u) => g.sample_split_at(wo, entering, Transport::Radiance, split, u, sh.ctx.rng),
                    None => g.sample_split(wo, entering, Transport::Radiance, split, sh.ctx.rng),
                };
                if split {
                    // The reflected branch by a gather of its own, the
                    // refracted one on in this loop.
                    splits -= 1;
                    // Further paths along it are drawn as the first (their
                    // refracted twins unused): the same expectation each.
                    // Where the reflected branch carries most of the light
                    // (by the surface's own normal, so the count is the
                    // same for every normal drawn), more paths along it.
                    let paths = match g.reflectance_about_normal(wo, entering) >= 0.5 {
                        true => self.settings.reflected_paths.max(1),
                        false => 1,
                    };
                    for path in 0..paths {
                        let reflected = match path {
                            0 => first,
                            _ => g.sample_split(wo, entering, Transport::Radiance, true, sh.ctx.rng)[0],
                        };
                        let Some((wi, gw)) = reflected else { continue };
                        let dir = frame.to_world(wi).normalize();
                        if y.shading_normal == y.normal || y.leaves_as(ray.dir, dir, true) {
                            let pdf = |g: Glossy<'_>| (1.0 - p_specular) * g.pdf(wo, wi, entering);
                            let sample = mis.map(|g| self.bsdf_sample(&y, frame.n, pdf(g)));
                            let (next, next_dep) = y.spawn(dir);
                            let weight = weight * gw / ((1.0 - p_specular) * paths as f32);
                            found += weight
                                * self.gather(next, next_dep, Lobe::Glossy, sample, splits, None, w * weight, sh);
                        }
                    }
                }
                let Some((wi, gw)) = (if split { second } else { first }) else { break };
                weight *= gw / (1.0 - p_specular);
                if caustic_glossy {
                    specular = true;
                } else {
                    (from, specular) = (Lobe::Glossy, false);
                }
                shared = mis.map(|g| self.bsdf_sample(&y, frame.n, (1.0 - p_specular) * g.pdf(wo, wi, entering)));
                frame.to_world(wi).normalize()
            };
            if y.shading_normal != y.normal && !y.leaves_as(ray.dir, next_dir, frame.to_local(next_dir).z > 0.0) {
                break;
            }
            (ray, dep) = y.spawn(next_dir);
        }
        found
    }

    /// The irradiance read at `point` (on a surface facing `normal`) times
    /// `weight`; or, where reads are deferred, zero, the read left for later
    /// with weight `w` times `weight` (`w`: what the radiance leaving along
    /// the gather ray is multiplied by on its way to the camera) and its
    /// cell's slot being fetched.
    pub(super) fn read(
        &self,
        point: glam::Vec3,
        normal: glam::Vec3,
        weight: Color,
        w: Color,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        if weight == Color::ZERO || self.cache.is_empty() {
            return Color::ZERO;
        }
        if self.settings.defer_reads {
            self.cache.prefetch_cell(point);
            sh.thread.pending.push(PendingRead { point, normal, weight: w * weight, ..Default::default() });
            Color::ZERO
        } else {
            weight * self.lookup(point, normal, self.cache.locate(point), sh.ctx)
        }
    }

    /// The cache's irradiance at `point` (in `cell`), from a cache point
    /// that no surface hides from it ([`IrradianceCache::lookup_seen`]):
    /// the shadow rays that asks for are counted.
    pub(super) fn lookup(&self, point: glam::Vec3, normal: glam::Vec3, cell: CellRange, ctx: &mut Context) -> Color {
        self.cache.lookup_seen(point, normal, cell, |from, to| {
            let (dir, len) = ((to - from).normalize_or_zero(), from.distance(to));
            ctx.counters.rays += 1;
            ctx.counters.cache_rays += 1;
            let blocked = self.scene.occluded(&Ray::new(from, dir), None, len, None);
            ctx.counters.cache_hidden += blocked as u64;
            blocked
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{next_2d, stream, Domain};

    /// A pixel's first 16 samples of 4 rays each put one ray's point in
    /// every cell of an 8 x 8 grid (the samples of all passes so far stay
    /// stratified), for any scramble; a sample's own 4 one in each
    /// quadrant.
    #[test]
    fn a_pixels_gather_points_stay_stratified_across_samples() {
        for scramble in [1u64, 0xDEAD_BEEF, u64::MAX / 3] {
            let mut cells = [0u32; 64];
            for index in 0..16 {
                let mut quadrants = [0u32; 4];
                for g in 0..4 {
                    let u = GatherSequence::new(index, scramble, 4).point(g);
                    assert!((0.0..1.0).contains(&u.x) && (0.0..1.0).contains(&u.y), "{u}");
                    cells[(u.y * 8.0) as usize * 8 + (u.x * 8.0) as usize] += 1;
                    quadrants[(u.y * 2.0) as usize * 2 + (u.x * 2.0) as usize] += 1;
                }
                assert_eq!(quadrants, [1; 4], "sample {index}, scramble {scramble:#x}");
            }
            assert_eq!(cells, [1; 64], "scramble {scramble:#x}");
        }
    }

    /// A block's points are the sequence's: point `index' * 4 + g` of the
    /// pixel's scrambled Sobol sequence.
    #[test]
    fn a_blocks_points_are_the_sequences() {
        let scramble = 0x1234_5678_9ABC_DEF0u64;
        let key = splitmix64(scramble ^ GATHER_SEQUENCE);
        for index in [0u64, 1, 7, 1000, 123_456] {
            let sample = shuffled_index(index as u32, (key >> 32) as u32);
            for g in 0..4 {
                let expected = crate::sampling::sobol_owen_2d(sample.wrapping_mul(4).wrapping_add(g), key);
                assert_eq!(GatherSequence::new(index, scramble, 3).point(g), expected, "{index}, {g}");
            }
        }
    }

    /// Within one pixel (one scramble), 3 rays of a block of 4 read every
    /// quarter of the square equally often over its samples: read from the
    /// block's start, one quarter would never be read (counts 1/3, 1/3,
    /// 1/3, 0).
    #[test]
    fn fewer_rays_than_the_block_read_all_of_it_in_each_pixel() {
        for scramble in [1u64, 0xDEAD_BEEF, u64::MAX / 3] {
            let (samples, mut quarters) = (4096u64, [0u32; 4]);
            for index in 0..samples {
                let q = GatherSequence::new(index, scramble, 4).rotated(3);
                for g in 0..3 {
                    quarters[(q.point(g).x * 4.0) as usize] += 1;
                }
            }
            for c in quarters {
                let share = c as f64 / (3 * samples) as f64;
                assert!((share - 0.25).abs() < 0.02, "{quarters:?}, scramble {scramble:#x}");
            }
        }
    }

    /// Two sequences read by the same 4 rays, the second from a random
    /// place: within one pixel, the rays' points pair every quarter of the
    /// first square with every quarter of the second, each about as
    /// often (read both from the start, 4 pairs of the 16 only).
    #[test]
    fn a_second_sequence_pairs_every_quarter_with_every_other_in_each_pixel() {
        let mut rng = stream(5, Domain::Camera, 0);
        for scramble in [1u64, 0xDEAD_BEEF] {
            let (samples, mut pairs) = (8192u64, [0u32; 16]);
            for index in 0..samples {
                let first = GatherSequence::new(index, scramble, 4).rotated(4);
                let second = GatherSequence::new(index, scramble ^ 0x77, 4).from_random_place(&mut rng);
                for g in 0..4 {
                    let (a, b) = (first.point(g), second.point(g));
                    pairs[(a.x * 4.0) as usize * 4 + (b.x * 4.0) as usize] += 1;
                }
            }
            for c in pairs {
                let share = c as f64 / (4 * samples) as f64;
                assert!((share - 1.0 / 16.0).abs() < 0.015, "{pairs:?}, scramble {scramble:#x}");
            }
        }
    }

    /// Over pixels (scrambles), samples and rays, the points are uniform:
    /// Pearson's chi-squared over a 10 x 10 grid (99 degrees of freedom;
    /// 149 is its 0.1% tail).
    #[test]
    fn gather_points_are_uniform() {
        let mut rng = stream(3, Domain::Camera, 0);
        let (n, bins) = (200_000usize, 10usize);
        let mut counts = vec![0f64; bins * bins];
        for i in 0..n {
            let r = next_2d(&mut rng);
            let scramble = crate::sampling::splitmix64(i as u64 / 64);
            let index = (r.x * 1000.0) as u64;
            let g = (r.y * 3.0) as u32;
            let u = GatherSequence::new(index, scramble, 3).point(g);
            counts[(u.y * bins as f32) as usize * bins + (u.x * bins as f32) as usize] += 1.0;
        }
        let expected = n as f64 / (bins * bins) as f64;
        let chi2: f64 = counts.iter().map(|c| (c - expected).powi(2) / expected).sum();
        assert!(chi2 < 149.0, "chi2 {chi2} over {} cells", bins * bins);
    }
}
