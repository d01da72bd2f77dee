//! The camera pass: every pixel of the film estimated by an integrator,
//! rows in parallel. Each pixel averages `spp` samples (a box filter),
//! placed by a [`Placement`]; pixels on the rim of a light's image
//! estimate the emitted part with `edge_spp` samples of their own. Each pixel has its own random
//! stream per pass, so rows can run on any thread in any order.

use super::adaptive::{allocate, Guide, Samples, PILOT_PASS};
use super::rims::{light_rims, Rims};
use crate::camera::Camera;
use crate::film::Film;
use crate::integrator::{Context, Integrator, Part};
use crate::progress::{Mode, Phase};
use crate::sampling::{next_2d, shuffled_index, sobol_owen_2d, splitmix64, stratified_2d, stream, Domain};
use crate::stats::Counters;
use glam::{DVec3, Vec2};
use rayon::prelude::*;

/// What a camera pass renders: the camera (at the film's resolution), the
/// samples per pixel, and the random streams' seed and pass.
#[derive(Clone, Copy, Debug)]
pub struct CameraPass {
    pub camera: Camera,
    pub spp: u32,
    /// Samples of the emitted part in pixels on the rim of a light's
    /// image (0: no rim pixels are looked for).
    pub edge_spp: u32,
    pub seed: u64,
    pub pass: u64,
    pub placement: Placement,
}

/// Where a pixel's samples fall.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// The CS475 course's n x n grid over the pixel, jittered (a line of
    /// jittered strata where the count is not a square), drawn anew each
    /// pass.
    JitteredGrid,
    /// A scrambled Sobol sequence that continues from pass to pass: the
    /// samples of all passes so far stay stratified (a sunlit patch's
    /// sharp border at 48 passes of 1 sample: the sun window's RMSE less
    /// the reference's noise -13%, notes/performance.md).
    Sobol,
}

/// A camera pass's film and what it counted.
pub struct Shot {
    pub film: Film,
    pub counters: Counters,
    /// Pixels on the rim of a light's image.
    pub edge_pixels: usize,
    /// The samples of the emitted part they took, on average (rounded
    /// down) and at most.
    pub edge_spp: u32,
    pub edge_spp_max: u32,
    /// Pixels given more samples than the pass's by the adaptive counts,
    /// and the samples added in all.
    pub adaptive_pixels: usize,
    pub adaptive_samples: u64,
}

/// The random-stream index of a pixel in a pass: passes get disjoint streams.
pub(crate) fn sample_index(pass: u64, pixel: u64) -> u64 {
    (pass << 40) | pixel
}

/// The scramble of a pixel's sample positions: its own for each pixel and
/// each part, the same in every pass, so that the passes continue one
/// stratified sequence.
fn pixel_scramble(seed: u64, pixel: u64, part: Part) -> u64 {
    splitmix64(splitmix64(seed ^ splitmix64(Domain::Camera as u64)) ^ splitmix64(pixel) ^ part as u64)
}

/// The scramble of a pixel's lens points, apart from its positions'.
fn lens_scramble(scramble: u64) -> u64 {
    splitmix64(scramble ^ 0x1E45_5A3F_1E45_5A3F)
}

/// Renders the film. The rim pixels are found once, by the probes of the
/// first pass given an empty `rims` (with the same random streams whatever
/// that pass is, so a render resumed at any pass finds the same), and kept: they are a property of the
/// scene and the image, not of a pass's photons. Which pixels take the
/// split estimate changes only its noise, not its mean. Found again every
/// pass, the probes (four camera rays a pixel) were 16-24% of a
/// progressive pass's camera pass at 1 spp.
///
/// The samples of the pixels' other part follow `guide.samples`
/// ([`super::adaptive`]): pass 0 always takes `spp` in every pixel; where
/// the counts are still to be measured it also traces each pixel's pilot
/// sample and fixes them for the passes after it.
pub fn camera_pass<I: Integrator>(pass: &CameraPass, integrator: &I, progress: Mode, guide: &mut Guide) -> Shot {
    let camera = &pass.camera;
    let (w, h) = (camera.width, camera.height);
    let spp = pass.spp.max(1);
    let lens = camera.projection.has_lens();
    let mut counters = Counters::default();
    let pilot = pass.pass == 0 && guide.needs_pilot();
    let counts = match (&guide.samples, pass.pass) {
        (Samples::Fixed(n), 1..) if n.len() == w as usize * h as usize => Some(n.clone()),
        _ => None,
    };
    let (adaptive_pixels, adaptive_samples) = counts.as_ref().map_or((0, 0), |n| {
        let more = n.iter().filter(|&&k| k > spp).count();
        (more, n.iter().map(|&k| k.saturating_sub(spp) as u64).sum())
    });
    // The pilot's squared difference and rays cast, per pixel.
    let mut diffs = vec![[0.0f32; 2]; w as usize * h as usize];
    let rims = guide.rims.get_or_insert_with(|| {
        if pass.edge_spp > 0 {
            light_rims(camera, integrator, pass.seed, &mut counters)
        } else {
            Rims::none(w as usize * h as usize)
        }
    });
    let edge_pixels = rims.count();
    let rim_spp = rims.samples(pass.edge_spp, w as usize * h as usize * spp as usize);
    let edge_total: u64 = rim_spp.iter().map(|&n| n as u64).sum();
    let edge_spp = if edge_pixels == 0 { pass.edge_spp } else { (edge_total / edge_pixels as u64) as u32 };
    let edge_spp_max = rim_spp.iter().copied().max().unwrap_or(0);
    let phase = Phase::start(progress, "camera pass", h as u64);
    let mut film = Film::new(w, h);
    let per_row: Vec<Counters> = film
        .pixels
        .par_chunks_mut(w as usize)
        .zip(diffs.par_chunks_mut(w as usize))
        .enumerate()
        .map_init(I::Thread::default, |thread, (row, (out, diffs))| {
            let row = row as u32;
            let mut counters = Counters::default();
            if crate::interrupt::requested() {
                // The pass is abandoned: its rows need not be finished.
                return counters;
            }
            for ((col, out), diff) in (0..w).zip(out).zip(diffs) {
                let pixel = row as u64 * w as u64 + col as u64;
                let mut rng = stream(pass.seed, Domain::Camera, sample_index(pass.pass, pixel));
                let mut state = I::Pixel::default();
                // The pixel's samples of its other part, and where in its
                // sequence they start: after pass 0's `spp`, `n` a pass
                // (`spp` · pass where the counts are even).
                let n = counts.as_ref().map_or(spp, |c| c[pixel as usize]);
                let first = match pass.pass {
                    0 => 0,
                    p => (spp as u64).wrapping_add((p - 1).wrapping_mul(n as u64)),
                };
                let mut estimate = |part: Part, n: u32, first: u64| {
                    let mut ctx = Context { rng: &mut rng, counters: &mut counters, pixel };
                    let scramble = pixel_scramble(pass.seed, pixel, part);
                    let mut sum = DVec3::ZERO;
                    for s in 0..n {
                        let index = first.wrapping_add(s as u64) as u32;
                        let u = match pass.placement {
                            Placement::JitteredGrid => stratified_2d(s, n, next_2d(ctx.rng)),
                            Placement::Sobol => sobol_owen_2d(index, scramble),
                        };
                        // A lens point per sample, from the pixel's own
                        // sequence (stratified over the lens as the
                        // positions are over the pixel, paired with them at
                        // random) or its random stream.
                        let on_lens = match pass.placement {
                            _ if !lens => Vec2::ZERO,
                            Placement::JitteredGrid => next_2d(ctx.rng),
                            Placement::Sobol => {
                                let l = lens_scramble(scramble);
                                sobol_owen_2d(shuffled_index(index, splitmix64(l) as u32), l)
                            }
                        };
                        let ray = camera.sample_ray(col, row, u, on_lens);
                        integrator.start_sample(&mut state, first.wrapping_add(s as u64), scramble);
                        sum += integrator.radiance(ray, part, &mut ctx, thread, &mut state).as_dvec3();
                    }
                    sum += integrator.finish(&mut ctx, thread, &mut state).as_dvec3();
                    sum / n as f64
                };
                let rim = rim_spp[pixel as usize];
                let part = if rim > 0 { Part::Reflected } else { Part::All };
                let other = estimate(part, n, first);
                let value = match rim {
                    0 => other,
                    _ => other + estimate(Part::Emitted, rim, pass.pass.wrapping_mul(rim as u64)),
                };
                *out = value.as_vec3();
                if pilot {
                    // One sample more of the same part, from a stream of
                    // its own (pass 0's image is as it was without it).
                    let mut rng = stream(pass.seed, Domain::Camera, sample_index(PILOT_PASS, pixel));
                    let u = next_2d(&mut rng);
                    let on_lens = if lens { next_2d(&mut rng) } else { Vec2::ZERO };
                    let ray = camera.sample_ray(col, row, u, on_lens);
                    let mut state = I::Pixel::default();
                    let before = counters.rays;
                    let mut ctx = Context { rng: &mut rng, counters: &mut counters, pixel };
                    let b = integrator.radiance(ray, part, &mut ctx, thread, &mut state).as_dvec3()
                        + integrator.finish(&mut ctx, thread, &mut state).as_dvec3();
                    let d = other - b;
                    let d2 = (d * d).element_sum() / 3.0;
                    let rays = (counters.rays - before) as f32;
                    *diff = [if d2.is_finite() { d2 as f32 } else { 0.0 }, rays];
                }
            }
            phase.advance(1);
            counters
        })
        .collect();
    phase.finish();
    let counters = per_row.into_iter().fold(counters, Counters::merge);
    if pilot && !crate::interrupt::requested() {
        let (diff, rays): (Vec<f32>, Vec<f32>) = diffs.iter().map(|&[d, r]| (d, r)).unzip();
        let n = allocate(&diff, &rays, w as usize, h as usize, spp);
        guide.samples = match n.iter().all(|&k| k == spp) {
            true => Samples::Even,
            false => Samples::Fixed(std::sync::Arc::new(n)),
        };
    }
    Shot { film, counters, edge_pixels, edge_spp, edge_spp_max, adaptive_pixels, adaptive_samples }
}
