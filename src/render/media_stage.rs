//! Photon mapping's pass in a scene with participating media: the global
//! and caustic photons traced through the media
//! ([`crate::photon::media_trace`]), the surface map and the two volume
//! maps built, the camera pass with [`VolPhotonIntegrator`] over them.
//! In a progressive render the surface map's k and radius cap shrink as
//! the other maps' do ([`Estimates::progressive`]), and every volume
//! photon's radius by the same factor: the beam estimate's kernel is a
//! disk about the ray, whose variance grows as 1 / r² and bias shrinks as
//! r², as a surface estimate's (Knaus and Zwicker 2011; Jarosz,
//! Nowrouzezahrai et al. 2011 for beams).

use super::camera_pass::CameraPass;
use super::method::shoot;
use super::photon_stage::{pass_seed, shrink, Estimates};
use crate::film::Film;
use crate::integrator::volphoton::VolPhotonIntegrator;
use crate::medium::Media;
use crate::photon::aims::specular_targets;
use crate::photon::map::PhotonMap;
use crate::photon::media_trace::trace_media_pass;
use crate::photon::trace::Pass;
use crate::photon::volume_map::VolumeMap;
use crate::progress::{Mode, Phase};
use crate::render::settings::Settings;
use crate::scene::Scene;
use crate::stats::Stats;
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
    rims: &mut Option<Vec<bool>>,
    stats: &mut Stats,
) -> Film {
    let est = Estimates::progressive(scene, settings, camera.pass as u32);
    (stats.r_global, stats.r_caustic, stats.k_global, stats.k_caustic) =
        (est.r_global, est.r_caustic, est.k_global, est.k_caustic);
    let seed = pass_seed(settings.seed, camera.pass);
    let targets = specular_targets(scene);
    let t = Instant::now();
    let phase = Phase::start(progress, "photon pass", settings.photons + settings.caustic_photons);
    let (global, caustic) = rayon::join(
        || trace_media_pass(scene, media, &targets, Pass::Global, settings.photons, seed, &|n| phase.advance(n)),
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
    let mut surface = global.surface;
    surface.extend(caustic.surface);
    let (surface, (volume, volume_caustic)) = rayon::join(
        || PhotonMap::build(surface),
        || {
            rayon::join(
                || VolumeMap::build(global.volume, VOLUME_K, r_volume, narrow),
                || VolumeMap::build(caustic.volume, VOLUME_K, r_volume, narrow),
            )
        },
    );
    stats.tree_time += t.elapsed();
    stats.global_stored = surface.len() + volume.len();
    stats.caustic_stored = volume_caustic.len();
    stats.map_bytes = surface.memory_bytes() + volume.memory_bytes() + volume_caustic.memory_bytes();
    let integrator = VolPhotonIntegrator {
        scene,
        media,
        surface: &surface,
        volume: &volume,
        volume_caustic: &volume_caustic,
        k: est.k_global,
        r_max: est.r_global,
        single_samples: SINGLE_SAMPLES,
    };
    shoot(camera, &integrator, progress, rims, stats)
}
