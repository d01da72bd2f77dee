//! The pipeline: scene → photon passes → maps → camera pass → film.

use crate::camera::Camera;
use crate::film::Film;
use crate::integrator::path::PathIntegrator;
use crate::integrator::photon::{PhotonEstimator, PhotonIntegrator};
use crate::integrator::{Context, Integrator, Part, PixelMemo, Tally};
use crate::math::max_component;
use crate::photon::irradiance_cache::IrradianceCache;
use crate::photon::map::PhotonMap;
use crate::photon::map::Scratch;
use crate::photon::trace::{trace_pass, Pass};
use crate::progress::{Mode, Phase};
use crate::sampling::{next_2d, stratified_2d, stream, Domain};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// The estimator a render uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Method {
    /// Photon mapping: direct light, caustic map, final gathering.
    #[default]
    Photon,
    /// Path tracing with next-event estimation (unbiased, the reference).
    Path,
}

/// Everything that decides the image besides the scene.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub method: Method,
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
    /// Irradiance is precomputed at every n-th global photon; `None`: at
    /// every (k_global / CACHE_POINTS_PER_DISK)-th ([`cache_stride`]).
    pub cache_stride: Option<usize>,
    /// A pixel's later samples reuse its last caustic estimate where they
    /// land on the same surface within this fraction of that estimate's
    /// radius (0: every sample makes its own).
    pub caustic_reuse: f32,
    /// Samples of the emitted part in pixels on the rim of a light's image.
    pub edge_spp: u32,
    /// Skip what the scene does not need (photon maps it cannot use, shadow
    /// rays towards lights facing away); off only to check the skips.
    pub skip: bool,
    /// Progressive photon mapping's radius shrinkage (Knaus & Zwicker 2011):
    /// pass i uses r_i^2 = r_1^2 * prod_{k<i} (k + alpha - 1) / k.
    pub alpha: f32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            method: Method::Photon,
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
            cache_stride: None,
            caustic_reuse: CAUSTIC_REUSE,
            edge_spp: 256,
            skip: true,
            alpha: 2.0 / 3.0,
        }
    }
}

/// The default [`Settings::caustic_reuse`].
pub const CAUSTIC_REUSE: f32 = 0.1;

/// Default caps on the search radius as fractions of the scene diagonal: the
/// k-nearest estimate sets the radius wherever photons are dense; the cap
/// only bounds the blur where they are sparse.
pub const GLOBAL_RADIUS_FRACTION: f32 = 0.05;
pub const CAUSTIC_RADIUS_FRACTION: f32 = 0.01;

impl Settings {
    /// Bytes the render will hold at its peak, estimated from the measured
    /// default scene: ~5 stored global photons per emitted one (Russian
    /// roulette with albedo 0.8), each 28 bytes plus ~16 in the kd-tree and
    /// as much again while the tree is built (a bound: a global map that
    /// keeps its grid builds no tree); one caustic photon per emitted
    /// one; the film in f32 and its rows in flight.
    pub fn estimated_peak_bytes(&self) -> u64 {
        let per_photon = std::mem::size_of::<crate::photon::Photon>() as u64 + 16 + 24;
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

/// Memory the system can give this process (Linux: MemAvailable), if known:
/// renders that would not fit are refused before they allocate.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
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
    /// The map build: the photon maps (the caustic map's Morton sort and
    /// kd-tree, both maps' grids), then the irradiance cache (estimates at
    /// photons, their grid and tree).
    pub tree_time: Duration,
    pub cache_time: Duration,
    pub camera_time: Duration,
    /// Radius caps and photons per estimate (of the last pass when progressive).
    pub r_global: f32,
    pub r_caustic: f32,
    pub k_global: usize,
    pub k_caustic: usize,
    /// Passes rendered (1 for a classic render).
    pub passes: u32,
    /// Photon maps the scene cannot use, not built.
    pub skipped_global: bool,
    pub skipped_caustic: bool,
    /// Shadow rays not cast towards lights facing away.
    pub shadow_rays_skipped: u64,
    /// Caustic estimates made by the camera pass, and those a pixel's
    /// earlier sample answered ([`Settings::caustic_reuse`]).
    pub caustic_estimates: u64,
    pub caustic_reused: u64,
}

impl Stats {
    pub fn build_time(&self) -> Duration {
        self.tree_time + self.cache_time
    }

    /// Adds another pass's counts and times (maps' sizes are the last pass's).
    fn absorb(&mut self, o: Stats) {
        self.global_emitted += o.global_emitted;
        self.caustic_emitted += o.caustic_emitted;
        self.caustic_aimed_hits += o.caustic_aimed_hits;
        self.global_specular_hits += o.global_specular_hits;
        self.photon_rays += o.photon_rays;
        self.camera_rays += o.camera_rays;
        self.nonfinite += o.nonfinite;
        self.first_nonfinite = self.first_nonfinite.or(o.first_nonfinite);
        self.photon_time += o.photon_time;
        self.tree_time += o.tree_time;
        self.cache_time += o.cache_time;
        self.camera_time += o.camera_time;
        self.global_stored = o.global_stored;
        self.caustic_stored = o.caustic_stored;
        self.cache_points = o.cache_points;
        self.map_bytes = o.map_bytes;
        self.edge_pixels = o.edge_pixels;
        self.r_global = o.r_global;
        self.r_caustic = o.r_caustic;
        self.k_global = o.k_global;
        self.k_caustic = o.k_caustic;
        self.passes += o.passes;
        self.skipped_global = o.skipped_global;
        self.skipped_caustic = o.skipped_caustic;
        self.shadow_rays_skipped += o.shadow_rays_skipped;
        self.caustic_estimates += o.caustic_estimates;
        self.caustic_reused += o.caustic_reused;
    }
}

/// The density-estimation settings of one photon-mapping pass: k nearest
/// photons within a radius cap, for the global (irradiance) and caustic maps.
#[derive(Clone, Copy, Debug)]
struct Estimates {
    k_global: usize,
    k_caustic: usize,
    r_global: f32,
    r_caustic: f32,
}

impl Estimates {
    /// Pass `i` (0-based; pass 0 is the classic render's settings): k and the
    /// squared radius cap scaled by s_i = prod_{k=1}^{i} (k + alpha - 1) / k. Per pass the
    /// variance grows as 1 / s_i and the bias shrinks as s_i, so the average
    /// of n passes has variance ~ n^-alpha and bias ~ n^(alpha-1) (Knaus &
    /// Zwicker 2011), while each estimate keeps adapting to the local density.
    /// k stays at least 2 (the estimators use the k-1 photons inside the rim).
    fn progressive(scene: &Scene, settings: &Settings, pass: u32) -> Self {
        let s: f64 = (1..=pass).map(|k| (k as f64 + settings.alpha as f64 - 1.0) / k as f64).product();
        let k = |k: usize| ((k as f64 * s).round() as usize).max(2);
        Estimates {
            k_global: k(settings.k_global),
            k_caustic: k(settings.k_caustic),
            r_global: settings.r_global(scene) * s.sqrt() as f32,
            r_caustic: settings.r_caustic(scene) * s.sqrt() as f32,
        }
    }
}

/// Precomputed irradiance values per k-nearest estimate disk, by default.
/// Gather rays read the nearest value, which lies, on average, towards where
/// photons (and so the values) are denser: the sparser the values, the more
/// that leans towards brighter neighbours. Measured (notes/performance.md):
/// at 6 per disk the default's mean moves by 0.02%; at 1.6 per disk (stride
/// 16 with the k = 25 of a 60th progressive pass) by +0.45%.
pub const CACHE_POINTS_PER_DISK: usize = 6;

/// The default stride: `CACHE_POINTS_PER_DISK` cached values per estimate
/// disk of `k_global` photons (16 at the default k = 100).
pub fn cache_stride(k_global: usize) -> usize {
    (k_global / CACHE_POINTS_PER_DISK).max(1)
}

/// The maps of one photon-mapping pass. The global map itself is dropped
/// once its irradiance is cached: the camera pass reads only the cache.
struct Maps {
    caustic: PhotonMap,
    cache: IrradianceCache,
}

/// Traces the photons of pass `pass` and builds its maps.
fn photon_pass(
    scene: &Scene,
    settings: &Settings,
    pass: u64,
    est: Estimates,
    progress: Mode,
    stats: &mut Stats,
) -> Maps {
    let seed = pass_seed(settings.seed, pass);
    let needs = scene.needs();
    stats.skipped_global = settings.skip && !needs.global;
    stats.skipped_caustic = settings.skip && !needs.caustics;
    let settings = &Settings {
        photons: if stats.skipped_global { 0 } else { settings.photons },
        caustic_photons: if stats.skipped_caustic { 0 } else { settings.caustic_photons },
        ..*settings
    };
    let t = Instant::now();
    let phase = Phase::start(progress, "photon pass", settings.photons + settings.caustic_photons);
    // Both passes at once: the threads that finish one pass's last blocks
    // early take the other's instead of waiting.
    let (global, caustic) = rayon::join(
        || trace_pass(scene, Pass::Global, settings.photons, seed, &|n| phase.advance(n)),
        || trace_pass(scene, Pass::Caustic, settings.caustic_photons, seed, &|n| phase.advance(n)),
    );
    phase.finish();
    stats.photon_time += t.elapsed();
    stats.global_emitted += global.emitted;
    stats.caustic_emitted += caustic.emitted;
    stats.caustic_aimed_hits += caustic.first_hit_specular;
    stats.global_specular_hits += global.first_hit_specular;
    stats.photon_rays += global.rays + caustic.rays;

    let t = Instant::now();
    // Caustic lookups run at every visible diffuse point and mostly near
    // the radius cap: the grid serves them (and rejects empty regions).
    // Global-map lookups run at photons (the irradiance cache), at radii
    // far below the cap: a finer grid serves most of them. The two builds
    // at once: each has serial stretches the other can fill.
    let (global_map, caustic_map) = rayon::join(
        || PhotonMap::build_for_photon_lookups(global.photons, est.r_global * GLOBAL_GRID_CELL),
        || {
            let map = PhotonMap::build_with_grid(caustic.photons, Some(est.r_caustic));
            if settings.skip {
                map
            } else {
                map.without_grid()
            }
        },
    );
    stats.tree_time += t.elapsed();
    let t = Instant::now();
    let stride = settings.cache_stride.unwrap_or_else(|| cache_stride(est.k_global));
    let cache = IrradianceCache::build(&global_map, stride, est.k_global, est.r_global);
    stats.cache_time += t.elapsed();
    stats.global_stored = global_map.len();
    stats.caustic_stored = caustic_map.len();
    stats.cache_points = cache.len();
    stats.map_bytes = global_map.memory_bytes() + caustic_map.memory_bytes();
    Maps { caustic: caustic_map, cache }
}

/// The global map's grid cells, as a fraction of its radius cap: sized
/// for the radius its estimates need (the k-th photon's distance, a few
/// percent of the cap where photons are dense), not for the cap. The
/// grid's cell budget widens them in a large scene, and where photons are
/// so dense that searches would read too many the map goes without.
pub const GLOBAL_GRID_CELL: f32 = 0.025;

/// The seed of pass `pass`: pass 0 uses the seed itself, so a one-pass
/// progressive render is the classic render's photon set.
fn pass_seed(seed: u64, pass: u64) -> u64 {
    if pass == 0 {
        seed
    } else {
        crate::sampling::splitmix64(seed ^ pass.wrapping_mul(0xA076_1D64_78BD_642F))
    }
}

fn photon_integrator<'a>(
    scene: &'a Scene,
    settings: &Settings,
    maps: &'a Maps,
    est: Estimates,
) -> PhotonIntegrator<'a> {
    PhotonIntegrator {
        scene,
        caustic: &maps.caustic,
        cache: &maps.cache,
        settings: PhotonEstimator {
            k_caustic: est.k_caustic,
            r_caustic: est.r_caustic,
            gather_rays: settings.gather_rays,
            shadow_rays: settings.shadow_rays,
            skip: settings.skip,
            caustic_reuse: settings.caustic_reuse,
        },
    }
}

/// Renders `scene` (its camera at `settings`' resolution) in one pass.
pub fn render(scene: &Scene, settings: &Settings, progress: Mode) -> (Film, Stats) {
    render_pass(scene, settings, 0, progress, &mut None)
}

/// Pass `pass` of a render: its own photons and camera samples, and (for
/// photon mapping) the estimates of [`Estimates::progressive`], which for
/// pass 0 are the classic ones. A one-pass render is pass 0. `rims`: the
/// pixels on the rim of a light's image, found by the first pass that
/// needs them and kept for the passes after it (see [`camera_pass`]).
fn render_pass(
    scene: &Scene,
    settings: &Settings,
    pass: u32,
    progress: Mode,
    rims: &mut Option<Vec<bool>>,
) -> (Film, Stats) {
    let mut stats = Stats { passes: 1, ..Stats::default() };
    let (film, tally, camera_time) = match settings.method {
        Method::Photon => {
            let est = Estimates::progressive(scene, settings, pass);
            (stats.r_global, stats.r_caustic, stats.k_global, stats.k_caustic) =
                (est.r_global, est.r_caustic, est.k_global, est.k_caustic);
            let maps = photon_pass(scene, settings, pass as u64, est, progress, &mut stats);
            let integrator = photon_integrator(scene, settings, &maps, est);
            timed(|| camera_pass(scene, settings, &integrator, pass as u64, progress, rims))
        }
        Method::Path => {
            let integrator = PathIntegrator { scene, shadow_rays: settings.shadow_rays, skip: settings.skip };
            timed(|| camera_pass(scene, settings, &integrator, pass as u64, progress, rims))
        }
    };
    stats.camera_time = camera_time;
    stats.camera_rays = tally.rays;
    stats.nonfinite = tally.nonfinite;
    stats.first_nonfinite = tally.first_nonfinite;
    stats.edge_pixels = tally.edge_pixels;
    stats.shadow_rays_skipped = tally.shadow_rays_skipped;
    stats.caustic_estimates = tally.caustic_estimates;
    stats.caustic_reused = tally.caustic_reused;
    (film, stats)
}

fn timed<T, U>(f: impl FnOnce() -> (T, U)) -> (T, U, Duration) {
    let t = Instant::now();
    let (a, b) = f();
    (a, b, t.elapsed())
}

/// When a progressive render stops.
#[derive(Clone, Copy, Debug)]
pub enum Budget {
    Passes(u32),
    /// Wall-clock seconds: no pass starts that the last pass's duration says
    /// would end past the budget (at least one pass always runs).
    Seconds(f64),
}

/// The state of a progressive render after a pass, for progress displays
/// and periodic output.
pub struct PassReport<'a> {
    pub film: &'a Film,
    pub passes: u32,
    pub elapsed: Duration,
    pub r_caustic: f32,
    pub r_global: f32,
    pub k_caustic: usize,
    pub k_global: usize,
}

/// Progressive rendering: independent passes, each with its own photons (or,
/// for path tracing, its own camera samples), averaged. Photon mapping's
/// estimates narrow from pass to pass (`Estimates::progressive`), so the
/// average converges to the true image. `on_pass` sees the running average
/// after every pass.
pub fn render_progressive(
    scene: &Scene,
    settings: &Settings,
    budget: Budget,
    mut on_pass: impl FnMut(&PassReport),
) -> (Film, Stats) {
    let start = Instant::now();
    let (w, h) = (settings.width, settings.height);
    let mut sum = vec![DVec3::ZERO; w as usize * h as usize];
    let mut stats = Stats::default();
    let mut pass = 0u32;
    let mut last_pass_time = Duration::ZERO;
    let mut rims = None;
    loop {
        let more = match budget {
            Budget::Passes(n) => pass < n.max(1),
            Budget::Seconds(s) => pass == 0 || (start.elapsed() + last_pass_time).as_secs_f64() <= s,
        };
        if !more {
            break;
        }
        let t = Instant::now();
        let (film, pass_stats) = render_pass(scene, settings, pass, Mode::Quiet, &mut rims);
        stats.absorb(pass_stats);
        for (acc, px) in sum.iter_mut().zip(&film.pixels) {
            *acc += px.as_dvec3();
        }
        pass += 1;
        last_pass_time = t.elapsed();
        let average = average_film(w, h, &sum, pass);
        on_pass(&PassReport {
            film: &average,
            passes: pass,
            elapsed: start.elapsed(),
            r_caustic: stats.r_caustic,
            r_global: stats.r_global,
            k_caustic: stats.k_caustic,
            k_global: stats.k_global,
        });
    }
    (average_film(w, h, &sum, pass), stats)
}

fn average_film(w: u32, h: u32, sum: &[DVec3], passes: u32) -> Film {
    Film { width: w, height: h, pixels: sum.iter().map(|s| (*s / passes.max(1) as f64).as_vec3()).collect() }
}

/// Camera rays traced per pixel to find the rim of the lights' images.
const PROBES: u32 = 4;

/// Which pixels see part of a light's surface and part of something else
/// (directly or through mirrors and glass): those whose probes disagree, or
/// whose neighbours' probes disagree with theirs (a rim thinner than the probe
/// spacing). The probes use their own random streams, so choosing the pixels
/// does not bias the samples that later estimate them.
fn light_rims(camera: &Camera, integrator: &impl Integrator, seed: u64, pass: u64, tally: &mut Tally) -> Vec<bool> {
    let (w, h) = (camera.width, camera.height);
    // Rows write into their stretch of one buffer: nothing is joined
    // serially afterwards (at 16 threads the serial stretches of this and
    // the camera pass were 3% of the pass).
    let mut counts = vec![0u8; w as usize * h as usize];
    let tallies: Vec<Tally> = counts
        .par_chunks_mut(w as usize)
        .enumerate()
        .map_init(Scratch::default, |scratch, (row, out)| {
            let row = row as u32;
            let mut tally = Tally::default();
            for (col, count) in (0..w).zip(out) {
                let pixel = row as u64 * w as u64 + col as u64;
                let mut rng = stream(seed, Domain::EdgeProbes, sample_index(pass, pixel));
                let mut memo = PixelMemo::default();
                *count = (0..PROBES)
                    .filter(|&s| {
                        let ray = camera.ray(col, row, stratified_2d(s, PROBES, next_2d(&mut rng)));
                        let mut ctx = Context::new(&mut rng, scratch, &mut tally, pixel, &mut memo, None);
                        max_component(integrator.radiance(ray, Part::Emitted, &mut ctx)) > 0.0
                    })
                    .count() as u8;
            }
            tally
        })
        .collect();
    for t in tallies {
        *tally = tally.merge(t);
    }
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

/// The random-stream index of a pixel in a pass: passes get disjoint streams.
fn sample_index(pass: u64, pixel: u64) -> u64 {
    (pass << 40) | pixel
}

/// Every pixel averages `spp` jittered samples (box filter); pixels on the
/// rim of a light's image estimate the emitted part with `edge_spp` samples
/// of their own. Each pixel has its own random stream per pass, so rows can
/// run on any thread in any order.
///
/// The rim pixels are found once, by the probes of the first pass given
/// an empty `rims`, and kept: they are a property of the scene and the
/// image, not of a pass's photons. Which pixels take the split estimate
/// changes only its noise, not its mean. Found again every pass, the
/// probes (four camera rays a pixel) were 16-24% of a progressive pass's
/// camera pass at 1 spp.
fn camera_pass(
    scene: &Scene,
    settings: &Settings,
    integrator: &impl Integrator,
    pass: u64,
    progress: Mode,
    rims: &mut Option<Vec<bool>>,
) -> (Film, Tally) {
    let (w, h) = (settings.width, settings.height);
    let camera = scene.camera.with_resolution(w, h);
    let spp = settings.spp.max(1);
    let mut tally = Tally::default();
    let rims: &[bool] = rims.get_or_insert_with(|| {
        if settings.edge_spp > 0 {
            light_rims(&camera, integrator, settings.seed, pass, &mut tally)
        } else {
            vec![false; w as usize * h as usize]
        }
    });
    tally.edge_pixels = rims.iter().filter(|&&r| r).count();
    let phase = Phase::start(progress, "camera pass", h as u64);
    let mut film = Film::new(w, h);
    let tallies: Vec<Tally> = film
        .pixels
        .par_chunks_mut(w as usize)
        .enumerate()
        .map_init(
            || (Scratch::default(), Vec::new()),
            |(scratch, pending), (row, out)| {
                let row = row as u32;
                let mut tally = Tally::default();
                for (col, out) in (0..w).zip(out) {
                    let pixel = row as u64 * w as u64 + col as u64;
                    let mut rng = stream(settings.seed, Domain::Camera, sample_index(pass, pixel));
                    let rim = rims[pixel as usize];
                    let mut memo = PixelMemo::default();
                    // The samples' cache reads are left for the end of the
                    // estimate and made together (`PendingRead`).
                    let mut estimate = |part: Part, n: u32| {
                        let mut ctx =
                            Context::new(&mut rng, scratch, &mut tally, pixel, &mut memo, Some(&mut *pending));
                        let mut sum = DVec3::ZERO;
                        for s in 0..n {
                            let ray = camera.ray(col, row, stratified_2d(s, n, next_2d(ctx.rng)));
                            sum += integrator.radiance(ray, part, &mut ctx).as_dvec3();
                        }
                        sum += integrator.resolve(&mut ctx).as_dvec3();
                        sum / n as f64
                    };
                    let value = if rim {
                        estimate(Part::Reflected, spp) + estimate(Part::Emitted, settings.edge_spp)
                    } else {
                        estimate(Part::All, spp)
                    };
                    *out = value.as_vec3();
                }
                phase.advance(1);
                tally
            },
        )
        .collect();
    phase.finish();
    for t in tallies {
        tally = tally.merge(t);
    }
    (film, tally)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::PendingRead;
    use crate::scene::Eye;

    /// The rim pixels are found by the first pass and used as they are by
    /// the passes after it (their probes are not cast again).
    #[test]
    fn later_passes_take_the_rims_they_are_given() {
        let scene = Scene::tncg15(Eye::One);
        let settings =
            Settings { photons: 5_000, caustic_photons: 5_000, width: 48, height: 48, spp: 1, ..Settings::default() };
        let mut rims = None;
        let (_, first) = render_pass(&scene, &settings, 0, Mode::Quiet, &mut rims);
        let found = rims.clone().expect("the first pass fills the rims");
        assert_eq!(first.edge_pixels, found.iter().filter(|&&r| r).count());
        assert!(first.edge_pixels > 0 && first.edge_pixels < 48 * 48 / 4, "{} rim pixels", first.edge_pixels);
        let (_, second) = render_pass(&scene, &settings, 1, Mode::Quiet, &mut rims);
        assert_eq!(rims.as_deref(), Some(&found[..]));
        assert_eq!(second.edge_pixels, first.edge_pixels);
        // Every pixel given as a rim takes the split estimate.
        let (_, all) = render_pass(&scene, &settings, 1, Mode::Quiet, &mut Some(vec![true; 48 * 48]));
        assert_eq!(all.edge_pixels, 48 * 48);
        assert!(all.camera_rays > second.camera_rays + 48 * 48 * 100);
    }

    /// Cache reads left for the end of a pixel and resolved together give
    /// what reads made at once give, to rounding: the weights they carry
    /// follow the camera path through glass (both branches at the first
    /// vertices, Fresnel's choice deeper) and mirrors. (The radiance scale
    /// of refraction cancels on the way in and out of the sphere, so this
    /// scene cannot tell whether it is carried.)
    #[test]
    fn pending_reads_resolve_to_the_reads_made_at_once() {
        let scene = Scene::tncg15(Eye::One);
        let settings = Settings { photons: 20_000, width: 48, height: 48, ..Settings::default() };
        let est = Estimates::progressive(&scene, &settings, 0);
        let maps = photon_pass(&scene, &settings, 0, est, Mode::Quiet, &mut Stats::default());
        let integrator = photon_integrator(&scene, &settings, &maps, est);
        let camera = scene.camera.with_resolution(48, 48);
        let (mut scratch, mut tally, mut pending) = (Scratch::default(), Tally::default(), Vec::<PendingRead>::new());
        let mut reads = 0;
        for pixel in 0..48 * 48u64 {
            let ray = camera.ray(pixel as u32 % 48, pixel as u32 / 48, glam::Vec2::splat(0.5));
            // Returns the radiance, and the reads left and their radiance.
            let mut run = |pending: Option<&mut Vec<PendingRead>>| {
                let (mut rng, mut memo) = (stream(3, Domain::Camera, pixel), PixelMemo::default());
                let mut ctx = Context::new(&mut rng, &mut scratch, &mut tally, pixel, &mut memo, pending);
                let radiance = integrator.radiance(ray, Part::All, &mut ctx);
                let left = ctx.pending.as_ref().map_or(0, |p| p.len());
                let resolved = integrator.resolve(&mut ctx);
                assert!(ctx.pending.as_ref().is_none_or(|p| p.is_empty()));
                (radiance, left, resolved)
            };
            let (at_once, none_left, _) = run(None);
            assert_eq!(none_left, 0);
            let (radiance, left, pending_radiance) = run(Some(&mut pending));
            reads += left;
            let resolved = radiance + pending_radiance;
            for c in 0..3 {
                let (a, b) = (at_once[c], resolved[c]);
                assert!((a - b).abs() <= 1e-5 * a.abs().max(1e-3), "pixel {pixel}: {at_once} at once, {resolved} left");
            }
        }
        assert!(reads > 4 * 48 * 48 / 2, "{reads} reads left");
    }
}
