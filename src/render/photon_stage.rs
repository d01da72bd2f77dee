//! Photon mapping as a render method: each pass's photon stage (trace the
//! global and caustic photons, build the caustic map and the global map's
//! irradiance cache), the camera pass's estimator over them, and its
//! lines of the summary.

use super::camera_pass::CameraPass;
use super::method::{shoot, Method, MethodSummary, RenderMethod};
use crate::film::Film;
use crate::integrator::photon::{PhotonEstimator, PhotonIntegrator};
use crate::integrator::{direct_irradiance, Context};
use crate::math::Color;
use crate::photon::aims::{disk_coverage, needs, specular_targets, Target};
use crate::photon::irradiance_cache::IrradianceCache;
use crate::photon::map::PhotonMap;
use crate::photon::spots::{bright_spots, Spot};
use crate::photon::trace::{trace_pass_with, Pass, Sequence};
use crate::photon::Photon;
use crate::progress::{Mode, Phase};
use crate::render::settings::{cache_stride, Settings};
use crate::sampling::{stream, Domain};
use crate::scene::Scene;
use crate::stats::{Counters, Stats};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Photon mapping: a pass is its photon stage ([`photon_pass`]) with the
/// pass's estimates ([`Estimates::progressive`]), then the camera pass
/// with the photon-mapping estimator over its maps.
pub struct PhotonMapping {
    pub settings: Settings,
}

impl RenderMethod for PhotonMapping {
    fn method(&self) -> Method {
        Method::Photon
    }

    fn pass(
        &self,
        scene: &Scene,
        camera: &CameraPass,
        progress: Mode,
        guide: &mut super::Guide,
        stats: &mut Stats,
    ) -> Film {
        let settings = &self.settings;
        if let Some(media) = scene.media() {
            return super::media_stage::media_pass(settings, scene, media, camera, progress, guide, stats);
        }
        let est = Estimates::progressive(scene, settings, camera.pass as u32);
        (stats.r_global, stats.r_caustic, stats.k_global, stats.k_caustic) =
            (est.r_global, est.r_caustic, est.k_global, est.k_caustic);
        let maps = photon_pass(scene, settings, camera.pass, est, progress, stats);
        let integrator = photon_integrator(scene, settings, &maps, est);
        shoot(camera, &integrator, progress, guide, stats)
    }

    fn summary(&self, s: &Stats) -> MethodSummary {
        let st = &self.settings;
        let secs = |d: Duration| d.as_secs_f64();
        let per_s = |n: u64, d: Duration| n as f64 / secs(d).max(1e-9) / 1e6;
        let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
        let last = if s.passes > 1 { " (last pass)" } else { "" };
        let mut out = vec![
            format!(
                "  global map   {:>11} emitted {:>11} stored{last}; {:.1}% first hit mirror/glass",
                s.global_emitted,
                s.global_stored,
                pct(s.global_specular_hits, s.global_emitted)
            ),
            format!(
                "  caustic map  {:>11} emitted {:>11} stored{last}; {:.1}% aimed hit mirror/glass",
                s.caustic_emitted,
                s.caustic_stored,
                pct(s.caustic_aimed_hits, s.caustic_emitted)
            ),
        ];
        // Light from outside: what share of the global pass met the scene.
        if s.global_landed < s.global_emitted {
            out.insert(
                1,
                format!("               {:.1}% of them landed on the scene", pct(s.global_landed, s.global_emitted)),
            );
        }
        if s.caustic_targets.len() > 1 {
            for (k, &(object, aimed, hit)) in s.caustic_targets.iter().enumerate().take(8) {
                out.push(format!(
                    "               target {k} (shape {object}): {:.1}% of {aimed} aimed hit mirror/glass",
                    pct(hit, aimed)
                ));
            }
            if s.caustic_targets.len() > 8 {
                out.push(format!("               ... and {} more targets", s.caustic_targets.len() - 8));
            }
        }
        out.push(format!(
            "               {:.1} MB of maps, {} cache points; radius caps {:.3} global, {:.3} caustic",
            s.map_bytes as f64 / 1e6,
            s.cache_points,
            s.r_global,
            s.r_caustic
        ));
        if s.spots > 0 {
            let plural = if s.spots == 1 { "" } else { "s" };
            out.push(format!("               {} bright spot{plural} for final gathering to aim at", s.spots));
        }
        out.push(format!(
            "  photon pass  {:>8.3} s  {:>7.2} M photons/s  {:>7.2} M rays/s",
            secs(s.photon_time),
            per_s(s.global_emitted + s.caustic_emitted, s.photon_time),
            per_s(s.photon_rays, s.photon_time)
        ));
        out.push(format!(
            "  map build    {:>8.3} s  (maps {:.3} s, irradiance cache {:.3} s, {} shadow rays)",
            secs(s.build_time()),
            secs(s.tree_time),
            secs(s.cache_time),
            s.cache_rays
        ));
        let camera = match st.aimed_rays() {
            0 => format!(", {} gather", st.gather_rays),
            aimed => format!(", {} gather ({aimed} aimed)", st.gather_rays),
        };
        let mut skipped = Vec::new();
        if s.skipped_global {
            skipped.push("the global map (nothing diffuse reflects light)".to_string());
        }
        if s.skipped_caustic {
            skipped.push("the caustic map (no mirror or glass, or nothing diffuse)".to_string());
        }
        MethodSummary { lines: out, camera, skipped }
    }
}

/// The density-estimation settings of one photon-mapping pass: k nearest
/// photons within a radius cap, for the global (irradiance) and caustic maps.
#[derive(Clone, Copy, Debug)]
pub struct Estimates {
    pub k_global: usize,
    pub k_caustic: usize,
    pub r_global: f32,
    pub r_caustic: f32,
}

impl Estimates {
    /// Pass `i` (0-based; pass 0 is the classic render's settings): k and the
    /// squared radius cap scaled by s_i = prod_{k=1}^{i} (k + alpha - 1) / k. Per pass the
    /// variance grows as 1 / s_i and the bias shrinks as s_i, so the average
    /// of n passes has variance ~ n^-alpha and bias ~ n^(alpha-1) (Knaus &
    /// Zwicker 2011), while each estimate keeps adapting to the local density.
    /// k stays at least 2 (the estimators use the k-1 photons inside the rim).
    pub fn progressive(scene: &Scene, settings: &Settings, pass: u32) -> Self {
        let s = shrink(settings.alpha, pass);
        let k = |k: usize| ((k as f64 * s).round() as usize).max(2);
        Estimates {
            k_global: k(settings.k_global),
            k_caustic: k(settings.k_caustic),
            r_global: settings.r_global(scene.diagonal()) * s.sqrt() as f32,
            r_caustic: settings.r_caustic(scene.diagonal()) * s.sqrt() as f32,
        }
    }
}

/// Pass `pass`'s shrink factor s_i = prod_{k=1}^{i} (k + alpha - 1) / k:
/// its estimates' k and squared radius caps relative to pass 0's.
pub fn shrink(alpha: f32, pass: u32) -> f64 {
    (1..=pass).map(|k| (k as f64 + alpha as f64 - 1.0) / k as f64).product()
}

/// The maps of one photon-mapping pass. The global map itself is dropped
/// once its irradiance is cached: the camera pass reads only the cache.
pub struct Maps {
    pub caustic: PhotonMap,
    pub cache: IrradianceCache,
    pub spots: Vec<Spot>,
    /// The scene's caustic targets, which final gathering aims at too.
    pub targets: Vec<Target>,
}

/// Traces the photons of pass `pass` and builds its maps.
pub fn photon_pass(
    scene: &Scene,
    settings: &Settings,
    pass: u64,
    est: Estimates,
    progress: Mode,
    stats: &mut Stats,
) -> Maps {
    let seed = pass_seed(settings.seed, pass);
    let targets = specular_targets(scene);
    let needs = needs(scene, &targets);
    stats.skipped_global = settings.skip && !needs.global;
    stats.skipped_caustic = settings.skip && !needs.caustics;
    let settings = &Settings {
        photons: if stats.skipped_global { 0 } else { settings.photons },
        caustic_photons: if stats.skipped_caustic { 0 } else { settings.caustic_photons },
        ..*settings
    };
    let t = Instant::now();
    let phase = Phase::start(progress, "photon pass", settings.photons + settings.caustic_photons);
    // The caustic photons of light at infinity: pass after pass along one
    // low-discrepancy sequence.
    let sequence = Sequence { seed: settings.seed, first: pass.wrapping_mul(settings.caustic_photons) };
    // Both passes at once: the threads that finish one pass's last blocks
    // early take the other's instead of waiting.
    let (global, caustic) = rayon::join(
        || trace_pass_with(scene, &targets, Pass::Global, settings.photons, seed, sequence, &|n| phase.advance(n)),
        || {
            let n = settings.caustic_photons;
            trace_pass_with(scene, &targets, Pass::Caustic, n, seed, sequence, &|n| phase.advance(n))
        },
    );
    phase.finish();
    stats.photon_time += t.elapsed();
    stats.global_emitted += global.emitted;
    stats.global_landed += global.landed;
    stats.caustic_emitted += caustic.emitted;
    stats.caustic_aimed_hits += caustic.first_hit_specular;
    if stats.caustic_targets.len() < targets.len() {
        stats.caustic_targets = targets.iter().map(|t| (t.object, 0, 0)).collect();
    }
    for (total, aimed) in stats.caustic_targets.iter_mut().zip(&caustic.aimed) {
        total.1 += aimed[0];
        total.2 += aimed[1];
    }
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
    let stride = settings.cache_stride.unwrap_or_else(|| cache_stride(est.k_global, global_map.len()));
    // Estimates near an edge or a contact are divided by the part of
    // their disk that lies on their surface.
    let coverage = |x, n, r| disk_coverage(scene, x, n, r, COVERAGE_SAMPLES);
    // The global map holds no photon's first hit: the cache adds the
    // direct light by shadow rays (counted, whichever thread casts them).
    let shadow_rays = AtomicU64::new(0);
    let direct = |i: u64, p: &Photon| {
        cache_direct(seed, i, &shadow_rays, |ctx| {
            direct_irradiance(scene, p.position(), p.surface_normal(), CACHE_SHADOW_RAYS, settings.skip, ctx)
        })
    };
    let cache = IrradianceCache::build_with(&global_map, stride, est.k_global, est.r_global, &coverage, Some(&direct));
    let spots = if settings.aimed_rays() > 0 {
        bright_spots(cache.spot_points(), |x, n| cache.lookup(x, n).element_sum() / 3.0)
    } else {
        Vec::new()
    };
    stats.cache_time += t.elapsed();
    stats.cache_rays += shadow_rays.into_inner();
    stats.spots = spots.len();
    stats.global_stored = global_map.len();
    stats.caustic_stored = caustic_map.len();
    stats.cache_points = cache.len();
    stats.map_bytes = global_map.memory_bytes() + caustic_map.memory_bytes();
    Maps { caustic: caustic_map, cache, spots, targets }
}

/// Shadow rays per area light for a cache point's direct irradiance.
pub(super) const CACHE_SHADOW_RAYS: u32 = 16;

/// The lights' irradiance at cache point `i` by `irradiance`, drawn from
/// point i's own stream (the same on any thread) with its shadow rays
/// counted into `rays`, whichever thread casts them.
pub(super) fn cache_direct(
    seed: u64,
    i: u64,
    rays: &AtomicU64,
    irradiance: impl FnOnce(&mut Context) -> Color,
) -> Color {
    let mut rng = stream(seed, Domain::CacheDirect, i);
    let mut counters = Counters::default();
    let e = irradiance(&mut Context { rng: &mut rng, counters: &mut counters, pixel: i });
    rays.fetch_add(counters.rays, Ordering::Relaxed);
    e
}

/// Rays measuring the part of an estimate's disk that lies on its surface
/// (where the disk holds another surface's photons).
pub(super) const COVERAGE_SAMPLES: u32 = 32;

/// The global map's grid cells, as a fraction of its radius cap: sized
/// for the radius its estimates need (the k-th photon's distance, a few
/// percent of the cap where photons are dense), not for the cap. The
/// grid's cell budget widens them in a large scene, and where photons are
/// so dense that searches would read too many the map goes without.
pub const GLOBAL_GRID_CELL: f32 = 0.025;

/// The seed of pass `pass`: pass 0 uses the seed itself, so a one-pass
/// progressive render is the classic render's photon set.
pub fn pass_seed(seed: u64, pass: u64) -> u64 {
    if pass == 0 {
        seed
    } else {
        crate::sampling::splitmix64(seed ^ pass.wrapping_mul(0xA076_1D64_78BD_642F))
    }
}

pub fn photon_integrator<'a>(
    scene: &'a Scene,
    settings: &Settings,
    maps: &'a Maps,
    est: Estimates,
) -> PhotonIntegrator<'a> {
    PhotonIntegrator {
        scene,
        caustic: &maps.caustic,
        cache: &maps.cache,
        spots: &maps.spots,
        targets: &maps.targets,
        settings: PhotonEstimator {
            k_caustic: est.k_caustic,
            r_caustic: est.r_caustic,
            gather_rays: settings.gather_rays,
            aimed_gather_rays: settings.aimed_rays(),
            shadow_rays: settings.shadow_rays,
            skip: settings.skip,
            caustic_reuse: settings.caustic_reuse,
            defer_reads: true,
            mis: true,
            rough_splits: crate::integrator::photon::ROUGH_SPLITS,
            reflected_paths: crate::integrator::photon::REFLECTED_PATHS,
            stratify_glossy: true,
            shadow_sequence_samples: settings.spp as u64,
        },
    }
}
