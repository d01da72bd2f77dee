//! The same seed gives a bit-identical image whatever the number of threads;
//! another seed gives another image. One harness, every configuration:
//! photon mapping, path tracing, and progressive photon mapping, through a
//! pinhole and through a thin lens (whose lens points are random numbers
//! too).

mod common;
use common::*;
use photonmap::camera::Projection;
use photonmap::film::Film;
use photonmap::render::{render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings};

fn on_threads(threads: usize, f: impl FnOnce() -> Film + Send) -> Film {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

fn check_thread_independence(render: impl Fn(u64) -> Film + Sync) {
    let one = on_threads(1, || render(9));
    assert_eq!(one, on_threads(2, || render(9)));
    assert_eq!(one, on_threads(3, || render(9)));
    assert_ne!(one, on_threads(2, || render(10)));
}

#[test]
fn path_tracing_is_thread_independent() {
    let scene = Scene::tncg15(Eye::One);
    let settings = Settings { method: Method::Path, spp: 2, width: 40, height: 40, ..Settings::default() };
    check_thread_independence(|seed| render_quiet(&scene, &Settings { seed, ..settings }));
}

#[test]
fn progressive_photon_mapping_is_thread_independent() {
    let scene = Scene::tncg15(Eye::One);
    let settings =
        Settings { photons: 10_000, caustic_photons: 10_000, spp: 1, width: 40, height: 40, ..Settings::default() };
    check_thread_independence(|seed| {
        render_progressive(&scene, &Settings { seed, ..settings }, Budget::passes(3), |_| {}).0
    });
}

#[test]
fn same_seed_same_image_on_1_2_and_3_threads() {
    let scene = Scene::tncg15(Eye::One);
    let mut settings = ci_settings(48);
    settings.photons = 20_000;
    settings.caustic_photons = 20_000;
    let run = |threads: usize, seed: u64| {
        let mut s = settings;
        s.seed = seed;
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| render_quiet(&scene, &s))
    };
    let one = run(1, 9);
    assert_eq!(one, run(2, 9));
    assert_eq!(one, run(3, 9));
    assert_ne!(one, run(2, 10));
}

#[test]
fn a_thin_lens_is_thread_independent() {
    let mut parts = Scene::tncg15_parts(Eye::One);
    parts.camera.projection = Projection::ThinLens { radius: 0.2, focus: 6.0 };
    let scene = Scene::from_parts(parts);
    let path = Settings { method: Method::Path, spp: 2, width: 40, height: 40, ..Settings::default() };
    check_thread_independence(|seed| render_quiet(&scene, &Settings { seed, ..path }));
    let photon =
        Settings { photons: 10_000, caustic_photons: 10_000, spp: 1, width: 40, height: 40, ..Settings::default() };
    check_thread_independence(|seed| {
        render_progressive(&scene, &Settings { seed, ..photon }, Budget::passes(2), |_| {}).0
    });
    // The lens is used: the image differs from the pinhole's.
    let pinhole = Scene::tncg15(Eye::One);
    assert_ne!(render_quiet(&scene, &path), render_quiet(&pinhole, &path));
}

/// Volumetric photon mapping, whose camera samples take their gather and
/// shadow rays' points from sequences of their pixel's: the same image on
/// any number of threads, in one pass and in two.
#[test]
fn volumetric_photon_mapping_is_thread_independent() {
    let (_, scene, _) = suite_scene("14-smoke");
    let settings =
        Settings { photons: 4_000, caustic_photons: 4_000, spp: 2, width: 20, height: 20, ..Settings::default() };
    check_thread_independence(|seed| render_quiet(&scene, &Settings { seed, ..settings }));
    check_thread_independence(|seed| {
        render_progressive(&scene, &Settings { seed, spp: 1, ..settings }, Budget::passes(2), |_| {}).0
    });
}
