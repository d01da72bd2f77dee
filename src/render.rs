//! The pipeline: scene → photon passes → maps → camera pass → film.

use crate::camera::Camera;
use crate::film::Film;
use crate::integrator::photon::{Context, Part, PhotonEstimator, PhotonIntegrator};
use crate::integrator::Tally;
use crate::math::max_component;
use crate::photon::map::Scratch;
use crate::photon::map::{IrradianceCache, PhotonMap};
use crate::photon::trace::{trace_pass, Pass};
use crate::progress::{Mode, Phase};
use crate::sampling::{next_2d, stratified_2d, stream, Domain};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Everything that decides the image besides the scene.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Photons emitted for the global map.
    pub photons: u64,
    /// Photons emitted (aimed at mirrors and glass) for the caustic map.
    pub caustic_photons: u64,
    /// Jittered camera samples per pixel.
    pub spp: u32,
    pub seed: u64,
    pub width: u32,
    pub height: u32,
    /// Nearest photons per global-map (irradiance) estimate.
    pub k_global: usize,
    /// Nearest photons per caustic estimate.
    pub k_caustic: usize,
    /// Search radius caps; `None`: a fraction of the scene's diagonal.
    pub r_global: Option<f32>,
    pub r_caustic: Option<f32>,
    pub gather_rays: u32,
    pub shadow_rays: u32,
    /// Irradiance is precomputed at every n-th global photon.
    pub cache_stride: usize,
    /// Samples of the emitted part in pixels on the rim of a light's image.
    pub edge_spp: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            photons: 1_000_000,
            caustic_photons: 1_000_000,
            spp: 4,
            seed: 1,
            width: 800,
            height: 800,
            k_global: 100,
            k_caustic: 100,
            r_global: None,
            r_caustic: None,
            gather_rays: 4,
            shadow_rays: 2,
            cache_stride: 4,
            edge_spp: 256,
        }
    }
}

/// Default caps on the search radius as fractions of the scene diagonal: the
/// k-nearest estimate sets the radius wherever photons are dense; the cap
/// only bounds the blur where they are sparse.
pub const GLOBAL_RADIUS_FRACTION: f32 = 0.05;
pub const CAUSTIC_RADIUS_FRACTION: f32 = 0.01;

impl Settings {
    /// Bytes the render will hold at its peak, estimated from the measured
    /// default scene: ~5 stored global photons per emitted one (Russian
    /// roulette with albedo 0.8), each 32 bytes plus ~16 in the kd-tree and
    /// as much again while the tree is built; one caustic photon per emitted
    /// one; the film in f32 and its rows in flight.
    pub fn estimated_peak_bytes(&self) -> u64 {
        let per_photon = 32 + 16 + 24;
        let global = self.photons.saturating_mul(5).saturating_mul(per_photon);
        let caustic = self.caustic_photons.saturating_mul(per_photon);
        let film = (self.width as u64) * (self.height as u64) * 2 * 12;
        global.saturating_add(caustic).saturating_add(film)
    }

    pub fn r_global(&self, scene: &Scene) -> f32 {
        self.r_global.unwrap_or(GLOBAL_RADIUS_FRACTION * scene.diagonal())
    }

    pub fn r_caustic(&self, scene: &Scene) -> f32 {
        self.r_caustic.unwrap_or(CAUSTIC_RADIUS_FRACTION * scene.diagonal())
    }
}

/// What a render did and what it cost.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub global_emitted: u64,
    pub global_stored: usize,
    pub caustic_emitted: u64,
    pub caustic_stored: usize,
    /// Caustic-pass photons whose first hit was mirror or glass.
    pub caustic_aimed_hits: u64,
    /// Global-pass photons whose first hit was mirror or glass (what the
    /// caustic pass would get without aiming).
    pub global_specular_hits: u64,
    pub cache_points: usize,
    pub map_bytes: usize,
    pub photon_rays: u64,
    pub camera_rays: u64,
    pub nonfinite: u64,
    /// Pixels on the rim of a light's image, sampled with `edge_spp`.
    pub edge_pixels: usize,
    pub first_nonfinite: Option<(u64, &'static str)>,
    pub photon_time: Duration,
    pub build_time: Duration,
    pub camera_time: Duration,
    pub r_global: f32,
    pub r_caustic: f32,
}

/// Renders `scene` (its camera at `settings`' resolution) with photon mapping.
pub fn render(scene: &Scene, settings: &Settings, progress: Mode) -> (Film, Stats) {
    let mut stats =
        Stats { r_global: settings.r_global(scene), r_caustic: settings.r_caustic(scene), ..Stats::default() };

    let t = Instant::now();
    let phase = Phase::start(progress, "photon pass", settings.photons + settings.caustic_photons);
    let global = trace_pass(scene, Pass::Global, settings.photons, settings.seed, &|n| phase.advance(n));
    let caustic = trace_pass(scene, Pass::Caustic, settings.caustic_photons, settings.seed, &|n| phase.advance(n));
    phase.finish();
    stats.photon_time = t.elapsed();
    stats.global_emitted = global.emitted;
    stats.caustic_emitted = caustic.emitted;
    stats.caustic_aimed_hits = caustic.first_hit_specular;
    stats.global_specular_hits = global.first_hit_specular;
    stats.photon_rays = global.rays + caustic.rays;

    let t = Instant::now();
    let global_map = PhotonMap::build(global.photons);
    let caustic_map = PhotonMap::build(caustic.photons);
    let cache = IrradianceCache::build(&global_map, settings.cache_stride, settings.k_global, stats.r_global);
    stats.build_time = t.elapsed();
    stats.global_stored = global_map.len();
    stats.caustic_stored = caustic_map.len();
    stats.cache_points = cache.len();
    stats.map_bytes = global_map.memory_bytes() + caustic_map.memory_bytes();

    let integrator = PhotonIntegrator {
        scene,
        caustic: &caustic_map,
        cache: &cache,
        settings: PhotonEstimator {
            k_caustic: settings.k_caustic,
            r_caustic: stats.r_caustic,
            gather_rays: settings.gather_rays,
            shadow_rays: settings.shadow_rays,
        },
    };
    let t = Instant::now();
    let (film, tally) = camera_pass(scene, settings, &integrator, progress);
    stats.camera_time = t.elapsed();
    stats.camera_rays = tally.rays;
    stats.edge_pixels = tally.edge_pixels;
    stats.nonfinite = tally.nonfinite;
    stats.first_nonfinite = tally.first_nonfinite;
    (film, stats)
}

/// Camera rays traced per pixel to find the rim of the lights' images.
const PROBES: u32 = 4;

/// Which pixels see part of a light's surface and part of something else
/// (directly or through mirrors and glass): those whose probes disagree, or
/// whose neighbours' probes disagree with theirs (a rim thinner than the probe
/// spacing). The probes use their own random streams, so choosing the pixels
/// does not bias the samples that later estimate them.
fn light_rims(camera: &Camera, integrator: &PhotonIntegrator, seed: u64, tally: &mut Tally) -> Vec<bool> {
    let (w, h) = (camera.width, camera.height);
    let rows: Vec<(Vec<u8>, Tally)> = (0..h)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, row| {
            let mut tally = Tally::default();
            let counts = (0..w)
                .map(|col| {
                    let pixel = row as u64 * w as u64 + col as u64;
                    let mut rng = stream(seed, Domain::EdgeProbes, pixel);
                    (0..PROBES)
                        .filter(|&s| {
                            let ray = camera.ray(col, row, stratified_2d(s, PROBES, next_2d(&mut rng)));
                            let mut ctx = Context { rng: &mut rng, scratch, tally: &mut tally, pixel };
                            max_component(integrator.radiance(ray, Part::Emitted, &mut ctx)) > 0.0
                        })
                        .count() as u8
                })
                .collect();
            (counts, tally)
        })
        .collect();
    let mut counts = Vec::with_capacity(w as usize * h as usize);
    for (c, t) in rows {
        counts.extend(c);
        *tally = tally.merge(t);
    }
    let at = |c: i64, r: i64| counts[(r * w as i64 + c) as usize];
    (0..h as i64)
        .flat_map(|r| (0..w as i64).map(move |c| (c, r)))
        .map(|(c, r)| {
            let own = at(c, r);
            if own > 0 && own < PROBES as u8 {
                return true;
            }
            (-1..=1).any(|dr| {
                (-1..=1).any(|dc| {
                    let (cc, rr) = (c + dc, r + dr);
                    cc >= 0 && rr >= 0 && cc < w as i64 && rr < h as i64 && at(cc, rr) != own
                })
            })
        })
        .collect()
}

/// Every pixel averages `spp` jittered samples (box filter); pixels on the
/// rim of a light's image estimate the emitted part with `edge_spp` samples
/// of their own. Each pixel has its own random stream, so rows can run on any
/// thread in any order.
fn camera_pass(scene: &Scene, settings: &Settings, integrator: &PhotonIntegrator, progress: Mode) -> (Film, Tally) {
    let (w, h) = (settings.width, settings.height);
    let camera = scene.camera.with_resolution(w, h);
    let spp = settings.spp.max(1);
    let mut tally = Tally::default();
    let rims = if settings.edge_spp > 0 {
        light_rims(&camera, integrator, settings.seed, &mut tally)
    } else {
        vec![false; (w * h) as usize]
    };
    tally.edge_pixels = rims.iter().filter(|&&r| r).count();
    let phase = Phase::start(progress, "camera pass", h as u64);
    let rows: Vec<(Vec<glam::Vec3>, Tally)> = (0..h)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, row| {
            let mut tally = Tally::default();
            let pixels = (0..w)
                .map(|col| {
                    let pixel = row as u64 * w as u64 + col as u64;
                    let mut rng = stream(settings.seed, Domain::Camera, pixel);
                    let rim = rims[pixel as usize];
                    let mut estimate = |part: Part, n: u32| {
                        let mut sum = DVec3::ZERO;
                        for s in 0..n {
                            let u = stratified_2d(s, n, next_2d(&mut rng));
                            let ray = camera.ray(col, row, u);
                            let mut ctx = Context { rng: &mut rng, scratch, tally: &mut tally, pixel };
                            sum += integrator.radiance(ray, part, &mut ctx).as_dvec3();
                        }
                        sum / n as f64
                    };
                    let value = if rim {
                        estimate(Part::Reflected, spp) + estimate(Part::Emitted, settings.edge_spp)
                    } else {
                        estimate(Part::All, spp)
                    };
                    value.as_vec3()
                })
                .collect();
            phase.advance(1);
            (pixels, tally)
        })
        .collect();
    phase.finish();
    let mut film = Film::new(w, h);
    film.pixels.clear();
    for (pixels, t) in rows {
        film.pixels.extend(pixels);
        tally = tally.merge(t);
    }
    (film, tally)
}
