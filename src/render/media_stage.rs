//! Photon mapping's pass in a scene with participating media: the global
//! and caustic photons traced through the media
//! ([`crate::photon::media_trace`]), the surface map, the global volume
//! photons' grid and the volume caustic map built, the camera pass with
//! [`VolPhotonIntegrator`] over them. In a progressive render the surface
//! map's k and radius cap shrink as the other maps' do
//! ([`Estimates::progressive`]), and every volume photon's radius (and
//! the global volume grid's cells) by the same factor: the beam
//! estimate's kernel is a disk about the ray, whose variance grows as
//! 1 / r² and bias shrinks as r², as a surface estimate's (Knaus and
//! Zwicker 2011; Jarosz, Nowrouzezahrai et al. 2011 for beams).
//!
//! With final gathering (`--gather-rays` above 0), the surface photons
//! after a diffuse lobe are left out of the map read at camera vertices
//! and all of them go into an irradiance cache that the gather rays read
//! ([`crate::integrator::volphoton`]).

use super::camera_pass::CameraPass;
use super::method::shoot;
use super::photon_stage::{
    cache_direct, pass_seed, shrink, Estimates, CACHE_SHADOW_RAYS, COVERAGE_SAMPLES, GLOBAL_GRID_CELL,
};
use crate::film::Film;
use crate::integrator::volgather::direct_irradiance_in_media;
use crate::integrator::volphoton::VolPhotonIntegrator;
use crate::medium::Media;
use crate::photon::aims::{disk_coverage, specular_targets};
use crate::photon::irradiance_cache::IrradianceCache;
use crate::photon::map::PhotonMap;
use crate::photon::media_trace::{medium_of, trace_media_pass, MAX_NAMED_MEDIA};
use crate::photon::trace::Pass;
use crate::photon::volume_grid::VolumeGrid;
use crate::photon::volume_map::{VolumeMap, SPARSE_RADIUS};
use crate::photon::Photon;
use crate::progress::{Mode, Phase};
use crate::render::settings::{cache_stride, Settings};
use crate::scene::Scene;
use crate::stats::Stats;
use std::sync::atomic::AtomicU64;
use std::time::Instant;

/// Nearest neighbours that set a volume photon's radius (Jarosz et al.
/// 2008 set it so too; fewer blur less and are noisier).
pub const VOLUME_K: usize = 24;

/// Single-scattering samples (shadow rays) per camera segment in a
/// medium: a shaft of light through a small window is met by few of them;
/// 8 cost less than the segment's beam estimates.
pub const SINGLE_SAMPLES: u32 = 8;

/// One pass of photon mapping in `scene`, whose media are `media`.
pub fn media_pass(
    settings: &Settings,
    scene: &Scene,
    media: &Media,
    camera: &CameraPass,
    progress: Mode,
    guide: &mut super::Guide,
    stats: &mut Stats,
) -> Film {
    let est = Estimates::progressive(scene, settings, camera.pass as u32);
    (stats.r_global, stats.r_caustic, stats.k_global, stats.k_caustic) =
        (est.r_global, est.r_caustic, est.k_global, est.k_caustic);
    let seed = pass_seed(settings.seed, camera.pass);
    let targets = specular_targets(scene);
    let t = Instant::now();
    let global_photons = settings.photons;
    let phase = Phase::start(progress, "photon pass", global_photons + settings.caustic_photons);
    let (global, caustic) = rayon::join(
        || trace_media_pass(scene, media, &targets, Pass::Global, global_photons, seed, &|n| phase.advance(n)),
        || {
            trace_media_pass(scene, media, &targets, Pass::Caustic, settings.caustic_photons, seed, &|n| {
                phase.advance(n)
            })
        },
    );
    phase.finish();
    stats.photon_time += t.elapsed();
    stats.global_emitted += global.emitted;
    stats.caustic_emitted += caustic.emitted;
    stats.photon_rays += global.rays + caustic.rays;

    let t = Instant::now();
    let narrow = shrink(settings.alpha, camera.pass as u32).sqrt() as f32;
    let r_volume = settings.r_global(scene.diagonal());
    let gathering =
        settings.gather_rays > 0 && !global.after_diffuse.is_empty() && media.media.len() <= MAX_NAMED_MEDIA;
    let mut surface = global.surface;
    surface.extend(caustic.surface);
    let mut after_diffuse = global.after_diffuse;
    let everything = if gathering {
        after_diffuse.extend_from_slice(&surface);
        after_diffuse
    } else {
        surface.extend(after_diffuse);
        Vec::new()
    };
    // The volume caustic photons sparser than their mean density (light
    // the glass scattered about the room, not its cone) join the global
    // volume photons' grid: read by the beam, their wide spheres were
    // most of what a camera segment crossed (notes/method.md §8).
    let mut global_volume = global.volume;
    let ((surface, cache_map), (volume, volume_caustic, sparse_caustic)) = rayon::join(
        || {
            rayon::join(
                || PhotonMap::build(surface),
                || gathering.then(|| PhotonMap::build_for_photon_lookups(everything, est.r_global * GLOBAL_GRID_CELL)),
            )
        },
        || {
            let (map, sparse) = VolumeMap::build_dense(caustic.volume, VOLUME_K, r_volume, narrow, SPARSE_RADIUS);
            let n = sparse.len();
            global_volume.extend(sparse);
            // A heterogeneous medium's grid reads the light apart from the
            // density, which is known exactly (notes/method.md §8).
            let extinction: Vec<_> = media
                .media
                .iter()
                .map(|med| (!med.is_homogeneous()).then_some(move |p| med.coefficients(p).0))
                .collect();
            let grid = VolumeGrid::build_weighed(&global_volume, VOLUME_K, r_volume, narrow, &extinction);
            (grid, map, n)
        },
    );
    stats.tree_time += t.elapsed();
    let t = Instant::now();
    // The cache's estimates near an edge or a contact are divided by the
    // part of their disk on their surface, and the lights' own irradiance
    // added by shadow rays, as in a scene without media; those carry the
    // transmittance from the medium each photon arrived through.
    let coverage = |x, n, r| disk_coverage(scene, x, n, r, COVERAGE_SAMPLES);
    let shadow_rays = AtomicU64::new(0);
    let direct = |i: u64, p: &Photon| {
        cache_direct(seed, i, &shadow_rays, |ctx| {
            let (x, n, m) = (p.position(), p.surface_normal(), medium_of(p));
            direct_irradiance_in_media(scene, media, x, n, m, CACHE_SHADOW_RAYS, ctx)
        })
    };
    let stride = |map: &PhotonMap| settings.cache_stride.unwrap_or_else(|| cache_stride(est.k_global, map.len()));
    let (cache, surface_cache) = rayon::join(
        || {
            cache_map.as_ref().map(|map| {
                IrradianceCache::build_with(map, stride(map), est.k_global, est.r_global, &coverage, Some(&direct))
            })
        },
        // The photons read at a diffuse camera vertex, cached as the
        // gathered ones are (less the lights' own irradiance, which shadow
        // rays count there).
        || {
            gathering.then(|| {
                IrradianceCache::build_with(&surface, stride(&surface), est.k_global, est.r_global, &coverage, None)
            })
        },
    );
    stats.cache_rays += shadow_rays.into_inner();
    let cache = cache.filter(|c| !c.is_empty());
    let surface_cache = surface_cache.filter(|c| !c.is_empty());
    stats.cache_time += t.elapsed();
    stats.cache_points = cache.as_ref().map_or(0, |c| c.len());
    stats.global_stored = cache_map.as_ref().map_or(surface.len(), |m| m.len()) + volume.len() - sparse_caustic;
    stats.caustic_stored = volume_caustic.len() + sparse_caustic;
    stats.map_bytes = surface.memory_bytes()
        + cache_map.as_ref().map_or(0, |m| m.memory_bytes())
        + volume.memory_bytes()
        + volume_caustic.memory_bytes();
    drop(cache_map);
    let integrator = VolPhotonIntegrator {
        scene,
        media,
        surface: &surface,
        cache: cache.as_ref(),
        surface_cache: surface_cache.as_ref(),
        gather_rays: settings.gather_rays,
        volume: &volume,
        volume_caustic: &volume_caustic,
        k: est.k_global,
        r_max: est.r_global,
        single_samples: SINGLE_SAMPLES,
        shadow_rays: settings.shadow_rays,
    };
    shoot(camera, &integrator, progress, guide, stats)
}
