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
/// spacing). The probes use their own random streams, so choosing the pixels
/// does not bias the samples that later estimate them.
pub(super) fn light_rims<I: Integrator>(
    camera: &Camera,
    integrator: &I,
    seed: u64,
    counters: &mut Counters,
) -> Vec<bool> {
    let (w, h) = (camera.width, camera.height);
    let lens = camera.projection.has_lens();
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
                let pixel = row as u64 * w as u64 + col as u64;
                let mut rng = stream(seed, Domain::EdgeProbes, sample_index(0, pixel));
                let mut state = I::Pixel::default();
                let mut ctx = Context { rng: &mut rng, counters: &mut row_counters, pixel };
                *count = (0..PROBES)
                    .filter(|&s| {
                        let u = stratified_2d(s, PROBES, next_2d(ctx.rng));
                        // Through the lens, a light's image blurs: its rim is
                        // where some of the lens sees it.
                        let on_lens = if lens { next_2d(ctx.rng) } else { Vec2::ZERO };
                        let ray = camera.sample_ray(col, row, u, on_lens);
                        let seen = integrator.radiance(ray, Part::Emitted, &mut ctx, thread, &mut state);
                        max_component(seen + integrator.finish(&mut ctx, thread, &mut state)) > 0.0
                    })
                    .count() as u8;
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
