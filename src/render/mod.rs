//! The pipeline: scene → photon stage (photon passes, maps) → camera pass
//! → film. A classic render is one pass; a progressive render averages
//! passes whose estimates narrow ([`progressive`]).

pub mod accumulation;
pub mod camera_pass;
pub mod error_estimate;
pub mod photon_stage;
pub mod progressive;
mod rims;

pub use camera_pass::{camera_pass, CameraPass, Placement};
pub use photon_stage::GLOBAL_GRID_CELL;
pub use progressive::{render_passes, render_progressive, Budget, PassReport, Run, Stopped};

use crate::film::Film;
use crate::integrator::path::PathIntegrator;
use crate::progress::Mode;
use crate::scene::Scene;
use crate::settings::{Method, Settings};
use crate::stats::Stats;
use photon_stage::{photon_integrator, photon_pass, Estimates};
use std::time::Instant;

/// Renders `scene` (its camera at `settings`' resolution) in one pass.
pub fn render(scene: &Scene, settings: &Settings, progress: Mode) -> (Film, Stats) {
    render_pass(scene, settings, 0, progress, &mut None)
}

/// Pass `pass` of a render: its own photons and camera samples, and (for
/// photon mapping) the estimates of [`Estimates::progressive`], which for
/// pass 0 are the classic ones. A one-pass render is pass 0. `rims`: the
/// pixels on the rim of a light's image, found by the first pass that
/// needs them and kept for the passes after it (see [`camera_pass`]).
pub(crate) fn render_pass(
    scene: &Scene,
    settings: &Settings,
    pass: u32,
    progress: Mode,
    rims: &mut Option<Vec<bool>>,
) -> (Film, Stats) {
    let mut stats = Stats { passes: 1, ..Stats::default() };
    let camera = CameraPass {
        camera: scene.camera.with_resolution(settings.width, settings.height),
        spp: settings.spp,
        edge_spp: settings.edge_spp,
        seed: settings.seed,
        pass: pass as u64,
        placement: Placement::Sobol,
    };
    let t = Instant::now();
    let shot = match settings.method {
        Method::Photon => {
            let est = Estimates::progressive(scene, settings, pass);
            (stats.r_global, stats.r_caustic, stats.k_global, stats.k_caustic) =
                (est.r_global, est.r_caustic, est.k_global, est.k_caustic);
            let maps = photon_pass(scene, settings, pass as u64, est, progress, &mut stats);
            let integrator = photon_integrator(scene, settings, &maps, est);
            let t = Instant::now();
            let shot = camera_pass(&camera, &integrator, progress, rims);
            stats.camera_time = t.elapsed();
            shot
        }
        Method::Path => {
            let integrator =
                PathIntegrator { scene, shadow_rays: settings.shadow_rays, skip: settings.skip, mis: true };
            let shot = camera_pass(&camera, &integrator, progress, rims);
            stats.camera_time = t.elapsed();
            shot
        }
    };
    stats.camera = shot.counters;
    stats.edge_pixels = shot.edge_pixels;
    (shot.film, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
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
        assert!(all.camera.rays > second.camera.rays + 48 * 48 * 100);
    }

    /// Cache reads left for the end of a pixel and resolved together give
    /// what reads made at once give, to rounding: the weights they carry
    /// follow the camera path through glass (both branches at the first
    /// vertices, Fresnel's choice deeper) and mirrors. (The radiance scale
    /// of refraction cancels on the way in and out of the sphere, so this
    /// scene cannot tell whether it is carried.)
    #[test]
    fn deferred_reads_resolve_to_the_reads_made_at_once() {
        use crate::integrator::{Context, Integrator};
        use crate::sampling::{stream, Domain};
        use crate::stats::Counters;
        let scene = Scene::tncg15(Eye::One);
        let settings = Settings { photons: 20_000, width: 48, height: 48, ..Settings::default() };
        let est = Estimates::progressive(&scene, &settings, 0);
        let maps = photon_pass(&scene, &settings, 0, est, Mode::Quiet, &mut Stats::default());
        let deferred = photon_integrator(&scene, &settings, &maps, est);
        let mut at_once = photon_integrator(&scene, &settings, &maps, est);
        at_once.settings.defer_reads = false;
        let camera = scene.camera.with_resolution(48, 48);
        let mut counters = Counters::default();
        let (mut thread, mut reads) = (Default::default(), 0);
        for pixel in 0..48 * 48u64 {
            let ray = camera.ray(pixel as u32 % 48, pixel as u32 / 48, glam::Vec2::splat(0.5));
            // At once, then deferred.
            let mut out = [(glam::Vec3::ZERO, glam::Vec3::ZERO); 2];
            for (integrator, out) in [&at_once, &deferred].into_iter().zip(&mut out) {
                let mut rng = stream(3, Domain::Camera, pixel);
                let mut ctx = Context { rng: &mut rng, counters: &mut counters, pixel };
                let mut state = Default::default();
                let radiance =
                    integrator.radiance(ray, crate::integrator::Part::All, &mut ctx, &mut thread, &mut state);
                let left = integrator.finish(&mut ctx, &mut thread, &mut state);
                *out = (radiance, left);
            }
            let [(a, none_left), (b, left)] = out;
            assert_eq!(none_left, glam::Vec3::ZERO);
            reads += (left != glam::Vec3::ZERO) as u32;
            let resolved = b + left;
            for c in 0..3 {
                let (x, y) = (a[c], resolved[c]);
                assert!((x - y).abs() <= 1e-5 * x.abs().max(1e-3), "pixel {pixel}: {a} at once, {resolved} deferred");
            }
        }
        assert!(reads > 48 * 48 / 2, "{reads} pixels left reads");
    }
}
