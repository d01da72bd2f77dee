//! The rim of the lights' images: pixels that see part of a light's
//! surface and part of something else, whose emitted part takes extra
//! samples (a bright light against a dark wall is most of a pixel's noise
//! there).

use super::camera_pass::sample_index;
use crate::camera::Camera;
use crate::integrator::{Context, Integrator, Part};
use crate::math::max_component;
use crate::sampling::{next_2d, stratified_2d, stream, Domain};
use crate::stats::Counters;
use glam::Vec2;
use rayon::prelude::*;

/// Camera rays traced per pixel to find the rim of the lights' images.
const PROBES: u32 = 4;

/// Which pixels see part of a light's surface and part of something else
/// (directly or through mirrors and glass): those whose probes disagree, or
/// whose neighbours' probes disagree with theirs (a rim thinner than the probe
/// spacing). None where the emitted part is no cheap part of a pixel's
/// estimate ([`emitted_part_is_cheap`]). The probes use their own random
/// streams, so choosing the pixels does not bias the samples that later
/// estimate them.
pub(super) fn light_rims<I: Integrator>(
    camera: &Camera,
    integrator: &I,
    seed: u64,
    counters: &mut Counters,
) -> Vec<bool> {
    let (w, h) = (camera.width, camera.height);
    if !emitted_part_is_cheap(camera, integrator, seed, counters) {
        counters.rims_too_costly += 1;
        return vec![false; w as usize * h as usize];
    }
    // Rows write into their stretch of one buffer: nothing is joined
    // serially afterwards (at 16 threads the serial stretches of this and
    // the camera pass were 3% of the pass).
    let mut counts = vec![0u8; w as usize * h as usize];
    let per_row: Vec<Counters> = counts
        .par_chunks_mut(w as usize)
        .enumerate()
        .map_init(I::Thread::default, |thread, (row, out)| {
            let row = row as u32;
            let mut row_counters = Counters::default();
            for (col, count) in (0..w).zip(out) {
                *count = probe_pixel(camera, integrator, seed, (col, row), thread, &mut row_counters);
            }
            row_counters
        })
        .collect();
    *counters = per_row.into_iter().fold(*counters, Counters::merge);
    let at = |c: i64, r: i64| counts[(r * w as i64 + c) as usize];
    let mut rims = vec![false; counts.len()];
    rims.par_chunks_mut(w as usize).enumerate().for_each(|(r, out)| {
        let r = r as i64;
        for (c, rim) in (0..w as i64).zip(out) {
            let own = at(c, r);
            *rim = (own > 0 && own < PROBES as u8)
                || (-1..=1).any(|dr| {
                    (-1..=1).any(|dc| {
                        let (cc, rr) = (c + dc, r + dr);
                        cc >= 0 && rr >= 0 && cc < w as i64 && rr < h as i64 && at(cc, rr) != own
                    })
                });
        }
    });
    rims
}

/// How many of a pixel's probes see emitted light (directly or through
/// mirrors and glass), from the pixel's own random stream.
fn probe_pixel<I: Integrator>(
    camera: &Camera,
    integrator: &I,
    seed: u64,
    (col, row): (u32, u32),
    thread: &mut I::Thread,
    counters: &mut Counters,
) -> u8 {
    let lens = camera.projection.has_lens();
    let pixel = row as u64 * camera.width as u64 + col as u64;
    let mut rng = stream(seed, Domain::EdgeProbes, sample_index(0, pixel));
    let mut state = I::Pixel::default();
    let mut ctx = Context { rng: &mut rng, counters, pixel };
    (0..PROBES)
        .filter(|&s| {
            let u = stratified_2d(s, PROBES, next_2d(ctx.rng));
            // Through the lens, a light's image blurs: its rim is where
            // some of the lens sees it.
            let on_lens = if lens { next_2d(ctx.rng) } else { Vec2::ZERO };
            let ray = camera.sample_ray(col, row, u, on_lens);
            let seen = integrator.radiance(ray, Part::Emitted, &mut ctx, thread, &mut state);
            max_component(seen + integrator.finish(&mut ctx, thread, &mut state)) > 0.0
        })
        .count() as u8
}

/// Whether the emitted part is the cheap part of a pixel's estimate, as
/// the split at the rims presumes: whether a pixel's `PROBES` probes cost
/// no more rays than one whole camera sample (a light seen directly or
/// through a few specular vertices, while a whole sample also gathers at
/// the diffuse surface it meets). Told from the probes of every
/// `SPARSE`-th pixel of every `SPARSE`-th row and a whole sample at every
/// other of those (0.3% of the rays of the default view's pass). Where the
/// emitted part costs more, each probe and each extra sample of it costs a
/// good part of a whole sample, and the probes alone more than another
/// sample of every pixel: in the TNCG15 room lined with mirrors (200 x 200,
/// 1e5 photons) a probe followed the mirrors for 24 rays against 45 for a
/// whole sample, the probes took 40% of a pass of 4 spp, and at equal
/// camera-pass time the image with rims had the higher RMSE
/// (notes/performance.md). The default view's probes cost 0.14 of a whole
/// sample, the suite's 0.12 to 0.19.
fn emitted_part_is_cheap<I: Integrator>(camera: &Camera, integrator: &I, seed: u64, counters: &mut Counters) -> bool {
    const SPARSE: u32 = 8;
    let lens = camera.projection.has_lens();
    let rows: Vec<u32> = (SPARSE / 2..camera.height).step_by(SPARSE as usize).collect();
    // Per row: the probes' rays and pixels, the whole samples' rays and count.
    let per_row: Vec<(Counters, [u64; 4])> = rows
        .par_iter()
        .map_init(I::Thread::default, |thread, &row| {
            let mut row_counters = Counters::default();
            let mut tally = [0; 4];
            for col in (SPARSE / 2..camera.width).step_by(SPARSE as usize) {
                let rays = row_counters.rays;
                probe_pixel(camera, integrator, seed, (col, row), thread, &mut row_counters);
                tally[0] += row_counters.rays - rays;
                tally[1] += 1;
                if (row / SPARSE + col / SPARSE).is_multiple_of(2) {
                    let pixel = row as u64 * camera.width as u64 + col as u64;
                    let mut rng = stream(seed, Domain::EdgeProbes, sample_index(1, pixel));
                    let mut state = I::Pixel::default();
                    let rays = row_counters.rays;
                    let mut ctx = Context { rng: &mut rng, counters: &mut row_counters, pixel };
                    let u = next_2d(ctx.rng);
                    let on_lens = if lens { next_2d(ctx.rng) } else { Vec2::ZERO };
                    let ray = camera.sample_ray(col, row, u, on_lens);
                    integrator.radiance(ray, Part::All, &mut ctx, thread, &mut state);
                    integrator.finish(&mut ctx, thread, &mut state);
                    tally[2] += row_counters.rays - rays;
                    tally[3] += 1;
                }
            }
            (row_counters, tally)
        })
        .collect();
    let tally = per_row.iter().fold([0; 4], |a, (_, t)| [a[0] + t[0], a[1] + t[1], a[2] + t[2], a[3] + t[3]]);
    *counters = per_row.into_iter().fold(*counters, |a, (c, _)| a.merge(c));
    // Probes' rays per pixel against a whole sample's: integers, so any
    // thread count decides alike.
    tally[1] == 0 || tally[3] == 0 || tally[0] * tally[3] <= tally[2] * tally[1]
}
