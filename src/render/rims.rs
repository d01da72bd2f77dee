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

/// Where every probe about a pixel sees emitted light, how much brighter
/// than the dimmest the brightest must be for the pixel to be a rim: a
/// bright light's image against a dim one's (a sun seen through glass, its
/// neighbours seeing the sky), whose pixels' emitted part is as noisy as a
/// light's against a dark wall. The variations of one light's image (its
/// Fresnel factors, a sky's gradient) stay well below it.
const CONTRAST: f32 = 16.0;

/// The rim pixels of a view, with how far apart the emitted light their
/// probes saw lies: for each pixel 0 where it is no rim, else the largest
/// value (the largest component) seen by the probes of the pixel and its
/// eight neighbours less the smallest (always above 0 at a rim: where
/// the probes disagree one saw nothing, else the brightest is `CONTRAST`
/// times the dimmest). A sample's spread bounds twice
/// its standard deviation, so it tells which rims are worth samples: a
/// sun seen through glass spreads 1,000 times as far as a sky seen past a
/// silhouette.
#[derive(Clone, Debug, PartialEq)]
pub struct Rims {
    spread: Vec<f32>,
}

/// A rim's samples where the rims share fewer than were asked: a part of
/// them spread evenly over every rim (a rim whose probes all missed a
/// thin bright image still takes a quarter of the even share) ...
const EVEN_PART: u64 = 4;
/// ... and none more than this many times what was asked (beyond it a
/// rim's noise is small against the rest of the image's).
const MOST_PER_ASKED: u32 = 16;

impl Rims {
    /// No rims, over `pixels` pixels.
    pub fn none(pixels: usize) -> Rims {
        Rims { spread: vec![0.0; pixels] }
    }

    /// The rims with these spreads (0: no rim).
    #[cfg(test)]
    pub(crate) fn from_spread(spread: Vec<f32>) -> Rims {
        Rims { spread: spread.into_iter().map(|s| if s > 0.0 { s } else { 0.0 }).collect() }
    }

    /// How many pixels are rims.
    pub fn count(&self) -> usize {
        self.spread.iter().filter(|&&s| s > 0.0).count()
    }

    /// The emitted part's samples in each pixel (0: no rim), `asked` a rim
    /// where the rims' share of the pass's other `samples`
    /// ([`rim_samples`]) allows it. Where it does not, the share is spent
    /// by the probes' spread: a quarter evenly, the rest in proportion to
    /// the spread (the allocation that minimises the summed variance of
    /// the rims' estimates is in proportion to their standard deviations),
    /// none above `MOST_PER_ASKED` times `asked`. Integers from the probes
    /// alone, in pixel order: the same on any number of threads and in
    /// every pass.
    pub(crate) fn samples(&self, asked: u32, samples: usize) -> Vec<u32> {
        let rims = self.count();
        let even = rim_samples(asked, samples, rims);
        if even >= asked {
            return self.spread.iter().map(|&s| if s > 0.0 { asked } else { 0 }).collect();
        }
        let budget = even as u64 * rims as u64;
        let floor = (even as u64 / EVEN_PART).max(1);
        let rest = budget.saturating_sub(floor * rims as u64) as f64;
        let total: f64 = self.spread.iter().map(|&s| s as f64).sum();
        let most = asked.saturating_mul(MOST_PER_ASKED).max(1) as u64;
        self.spread
            .iter()
            .map(|&s| match s > 0.0 {
                true => (floor + (rest * s as f64 / total) as u64).min(most) as u32,
                false => 0,
            })
            .collect()
    }
}

/// The emitted part's even share a rim: `asked`, but no more than the
/// pass's other `samples` spread over the `rims` (at least one). The split
/// is worth its cost where a few rim pixels hold most of the noise (a small
/// bright light, notes/method.md); where a rim runs along every silhouette
/// (a scene lit by an environment map, 499 to 829 of 48 x 48 pixels in
/// Mitsuba's media tests) 256 samples each made a pass of 1 spp cost 4.4x
/// as much. Fixed by the rims, not the pass, so that every pass takes the
/// same count and the Sobol sequence runs on.
pub(crate) fn rim_samples(asked: u32, samples: usize, rims: usize) -> u32 {
    if rims == 0 {
        return asked;
    }
    asked.min((samples / rims).clamp(1, u32::MAX as usize) as u32)
}

/// What a pixel's probes saw of the emitted part: how many saw any, the
/// smallest and the largest value.
#[derive(Clone, Copy, Default)]
struct Probed {
    count: u8,
    low: f32,
    high: f32,
}

/// Which pixels see part of a light's surface and part of something else
/// (directly or through mirrors and glass): those whose probes disagree, or
/// whose neighbours' probes disagree with theirs (a rim thinner than the probe
/// spacing), with their spread ([`Rims`]). None where the emitted part is
/// no cheap part of a pixel's estimate ([`emitted_part_is_cheap`]). The
/// probes use their own random streams, so choosing the pixels and their
/// samples does not bias the samples that later estimate them.
pub(super) fn light_rims<I: Integrator>(camera: &Camera, integrator: &I, seed: u64, counters: &mut Counters) -> Rims {
    let (w, h) = (camera.width, camera.height);
    if !emitted_part_is_cheap(camera, integrator, seed, counters) {
        counters.rims_too_costly += 1;
        return Rims::none(w as usize * h as usize);
    }
    // Rows write into their stretch of one buffer: nothing is joined
    // serially afterwards (at 16 threads the serial stretches of this and
    // the camera pass were 3% of the pass).
    let mut probed = vec![Probed::default(); w as usize * h as usize];
    let per_row: Vec<Counters> = probed
        .par_chunks_mut(w as usize)
        .enumerate()
        .map_init(I::Thread::default, |thread, (row, out)| {
            let row = row as u32;
            let mut row_counters = Counters::default();
            for (col, p) in (0..w).zip(out) {
                *p = probe_pixel(camera, integrator, seed, (col, row), thread, &mut row_counters);
            }
            row_counters
        })
        .collect();
    *counters = per_row.into_iter().fold(*counters, Counters::merge);
    let at = |c: i64, r: i64| probed[(r * w as i64 + c) as usize];
    let mut spread = vec![0.0f32; probed.len()];
    spread.par_chunks_mut(w as usize).enumerate().for_each(|(r, out)| {
        let r = r as i64;
        for (c, out) in (0..w as i64).zip(out) {
            let own = at(c, r);
            let around = (-1..=1)
                .flat_map(|dr| (-1..=1).map(move |dc| (c + dc, r + dr)))
                .filter(|&(cc, rr)| cc >= 0 && rr >= 0 && cc < w as i64 && rr < h as i64)
                .map(|(cc, rr)| at(cc, rr));
            let (low, high) = around.clone().fold((own.low, own.high), |(l, h), p| (l.min(p.low), h.max(p.high)));
            let rim = (own.count > 0 && own.count < PROBES as u8)
                || around.clone().any(|p| p.count != own.count)
                || (low > 0.0 && high > CONTRAST * low);
            if rim {
                *out = (high - low).max(f32::MIN_POSITIVE);
            }
        }
    });
    Rims { spread }
}

/// What a pixel's probes see of emitted light (directly or through mirrors
/// and glass), from the pixel's own random stream.
fn probe_pixel<I: Integrator>(
    camera: &Camera,
    integrator: &I,
    seed: u64,
    (col, row): (u32, u32),
    thread: &mut I::Thread,
    counters: &mut Counters,
) -> Probed {
    let lens = camera.projection.has_lens();
    let pixel = row as u64 * camera.width as u64 + col as u64;
    let mut rng = stream(seed, Domain::EdgeProbes, sample_index(0, pixel));
    let mut state = I::Pixel::default();
    let mut ctx = Context { rng: &mut rng, counters, pixel };
    let mut probed = Probed { count: 0, low: f32::INFINITY, high: 0.0 };
    for s in 0..PROBES {
        let u = stratified_2d(s, PROBES, next_2d(ctx.rng));
        // Through the lens, a light's image blurs: its rim is where
        // some of the lens sees it.
        let on_lens = if lens { next_2d(ctx.rng) } else { Vec2::ZERO };
        let ray = camera.sample_ray(col, row, u, on_lens);
        let seen = integrator.radiance(ray, Part::Emitted, &mut ctx, thread, &mut state);
        let value = max_component(seen + integrator.finish(&mut ctx, thread, &mut state));
        // Not a number or below zero counts as nothing seen.
        let value = if value > 0.0 { value } else { 0.0 };
        probed.count += (value > 0.0) as u8;
        probed.low = probed.low.min(value);
        probed.high = probed.high.max(value);
    }
    probed
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

#[cfg(test)]
mod tests {
    use super::{rim_samples, Rims, EVEN_PART, MOST_PER_ASKED};
    use crate::progress::Mode;
    use crate::render::render_pass;
    use crate::render::settings::Settings;
    use crate::scene::Scene;

    /// A few rims take what is asked; many share the pass's other samples;
    /// every rim takes at least one.
    #[test]
    fn rims_take_at_most_the_passs_other_samples() {
        assert_eq!(rim_samples(256, 800 * 800 * 4, 905), 256);
        assert_eq!(rim_samples(256, 48 * 48, 499), 4);
        assert_eq!(rim_samples(256, 48 * 48, 48 * 48), 1);
        assert_eq!(rim_samples(0, 48 * 48, 10), 0);
        assert_eq!(rim_samples(256, 10, 0), 256);
    }

    /// Where the rims' share allows, each takes what is asked, whatever its
    /// spread; where it does not, the share goes by the spread: no more in
    /// all than the share, a quarter of the even share at least, in
    /// proportion beyond it, none above the cap.
    #[test]
    fn a_short_share_goes_by_the_spread() {
        let mut spread = vec![0.0; 1000];
        spread[..100].fill(1.0);
        spread[100] = 1000.0;
        spread[101] = 2.0;
        let rims = Rims::from_spread(spread);
        assert_eq!(rims.count(), 102);
        let plenty = rims.samples(256, 102 * 256);
        assert!(plenty[..102].iter().all(|&n| n == 256) && plenty[102..].iter().all(|&n| n == 0));
        let share = 102 * 40;
        let n = rims.samples(256, share);
        let total: u32 = n.iter().sum();
        assert!(total <= share as u32 && total + 102 >= share as u32, "{total} of {share}");
        assert!(n[102..].iter().all(|&k| k == 0));
        assert!(n[..102].iter().all(|&k| k >= 40 / EVEN_PART as u32), "{n:?}");
        assert!(n[100] > 20 * n[0] && n[101] > n[0], "{} {} {}", n[100], n[101], n[0]);
        // A share so large against the cap that the brightest rim is held
        // to it, and what it leaves is not spent elsewhere.
        let capped = rims.samples(4, 102 * 3);
        assert_eq!(capped[100], 4 * MOST_PER_ASKED);
        assert!(capped.iter().sum::<u32>() <= 102 * 3);
    }

    /// A small bright disk seen through a glass ball on a floor under a dim
    /// sky: the pixels that see the disk through the glass are rims (every
    /// probe there sees emitted light, the sky reflected or refracted, so
    /// only their contrast tells them) and take more of the emitted part's
    /// samples than the rims where the sky is seen or not (the ball's
    /// lower outline and the floor's far edge against the sky). Before,
    /// none there was a rim and every rim took the same.
    #[test]
    fn a_bright_light_seen_through_glass_takes_more_samples_than_a_dim_silhouette() {
        let text = r#"
[camera]
eye = [0, -4, 1]
target = [0, 0, 0]
up = [0, 0, 1]
vfov = 70
width = 64
height = 64

[materials.floor]
type = "lambertian"
rho = [0.5, 0.5, 0.5]

[materials.glass]
type = "glass"
ior = 1.5

[[shapes]]
type = "quad"
vertices = [[-10, -10, -1.001], [10, -10, -1.001], [10, 2, -1.001], [-10, 2, -1.001]]
material = "floor"

[[shapes]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "glass"

[[lights]]
type = "sky"
radiance = [0.5, 0.5, 0.5]

[[lights]]
type = "disk"
center = [0, 12, -2]
normal = [0, -0.97, 0.2425]
radius = 0.5
radiance = [2000, 2000, 2000]
"#;
        let file = crate::scene::file::parse(text, std::path::Path::new("ball.toml")).unwrap();
        let scene = Scene::from_parts(file.parts);
        let settings =
            Settings { photons: 2_000, caustic_photons: 2_000, width: 64, height: 64, spp: 1, ..Settings::default() };
        let unit = settings.method.unit(&settings);
        let mut guide = crate::render::Guide::default();
        render_pass(&scene, &settings, unit.as_ref(), 0, Mode::Quiet, &mut guide);
        let rims = guide.rims.expect("the pass finds the rims");
        let n = rims.samples(settings.edge_spp, 64 * 64);
        // The ball's image: a disk about the centre, 12 pixels in radius
        // (its angular radius asin(1/4) against the half field of 35
        // degrees), the disk light's image through it within 5 of the
        // centre; the other rims are the ball's lower outline and the
        // floor's far edge, against the sky.
        let (mut inside, mut outline) = (Vec::new(), Vec::new());
        for (i, &k) in n.iter().enumerate().filter(|(_, &k)| k > 0) {
            let (x, y) = ((i % 64) as f32 + 0.5 - 32.0, (i / 64) as f32 + 0.5 - 32.0);
            match (x * x + y * y).sqrt() {
                d if d < 6.0 => inside.push(k),
                d if d > 7.0 => outline.push(k),
                _ => {}
            }
        }
        let mean = |v: &[u32]| v.iter().sum::<u32>() as f64 / v.len().max(1) as f64;
        assert!(inside.len() > 5 && outline.len() > 100, "{} inside, {} on the outline", inside.len(), outline.len());
        assert!(mean(&inside) > 8.0 * mean(&outline), "{inside:?} against {outline:?}");
    }
}
