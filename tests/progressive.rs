//! Progressive photon mapping converges, and the path tracer agrees with the
//! independent reference within noise; both at CI-sized budgets.

mod common;
use common::*;
use photonmap::metrics::compare;
use photonmap::progress::Mode;
use photonmap::render::{render, render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings};

fn progressive(passes: u32) -> photonmap::metrics::Metrics {
    let scene = Scene::tncg15(Eye::One);
    let settings =
        Settings { photons: 50_000, caustic_photons: 50_000, spp: 1, width: 200, height: 200, ..Settings::default() };
    let mut seen = 0;
    let (film, stats) = render_progressive(&scene, &settings, Budget::passes(passes), |r| {
        seen += 1;
        assert_eq!(r.passes, seen);
        assert!(r.film.pixels.iter().all(|c| c.is_finite()));
    });
    assert_eq!((stats.passes, seen), (passes, passes));
    assert_eq!(stats.camera.nonfinite, 0);
    compare(&film, &reference("default_e1_200.exr")).unwrap()
}

#[test]
fn more_passes_come_closer_to_the_reference() {
    let (short, long) = (progressive(2), progressive(8));
    eprintln!("2 passes: {short:?}\n8 passes: {long:?}");
    // 4x the passes: the error must fall clearly (1/sqrt(4) for the noise
    // alone; we ask for 1.4x), for the whole image and the caustic.
    assert!(long.rmse * 1.4 < short.rmse, "rmse {} -> {}", short.rmse, long.rmse);
    assert!(long.caustic_rmse * 1.4 < short.caustic_rmse, "caustic {} -> {}", short.caustic_rmse, long.caustic_rmse);
    for m in [short, long] {
        assert!((m.mean_x / m.mean_r - 1.0).abs() < 0.02, "mean {} vs {}", m.mean_x, m.mean_r);
    }
}

/// Student's t-test: 8 independent path-traced renders (8 spp, 200²); their
/// whole-image and caustic-window means must agree with the reference's
/// within 5.41 standard errors (two-sided 99.9% with 7 degrees of freedom).
#[test]
fn path_tracer_agrees_with_the_reference_within_noise() {
    let scene = Scene::tncg15(Eye::One);
    let reference = reference("default_e1_200.exr");
    let runs: Vec<(f64, f64)> = (0..8)
        .map(|seed| {
            let s = Settings { method: Method::Path, spp: 8, width: 200, height: 200, seed, ..Settings::default() };
            let (film, stats) = render(&scene, &s, Mode::Quiet);
            assert_eq!(stats.camera.nonfinite, 0);
            let m = compare(&film, &reference).unwrap();
            (m.mean_x, m.caustic_mean_x)
        })
        .collect();
    let m0 = compare(&reference, &reference).unwrap();
    for (which, truth) in [(0, m0.mean_r), (1, m0.caustic_mean_r)] {
        let xs: Vec<f64> = runs.iter().map(|r| if which == 0 { r.0 } else { r.1 }).collect();
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let se = (var / n).sqrt();
        let t = (mean - truth) / se;
        eprintln!("{}: {mean:.5} vs {truth:.5}, se {se:.5}, t = {t:.2}", ["image mean", "caustic mean"][which]);
        assert!(t.abs() < 5.41, "t = {t}");
        // And the noise itself is small: the test has power.
        assert!(se / truth < [0.005, 0.05][which], "se {se}");
    }
}

/// Gather rays read the nearest precomputed irradiance: the sparser the
/// cached values, the further the image from caching at every photon
/// (with the small k of late progressive passes, 25 here, a stride of 64
/// left holes between the points and darkened the image by ~4%). The
/// default stride follows k (k / 6) and stays within 0.25% of caching at
/// every photon.
#[test]
fn the_irradiance_cache_stays_dense_enough_as_k_shrinks() {
    let scene = Scene::tncg15(Eye::One);
    let mean = |stride: Option<usize>| {
        let s = Settings {
            photons: 100_000,
            caustic_photons: 100_000,
            spp: 1,
            width: 100,
            height: 100,
            k_global: 25,
            cache_stride: stride,
            ..Settings::default()
        };
        render(&scene, &s, Mode::Quiet).0.mean()
    };
    let every = mean(Some(1));
    let (auto, sparse) = (mean(None) / every - 1.0, mean(Some(64)) / every - 1.0);
    eprintln!("mean against stride 1: default {auto:+.4}, stride 64 {sparse:+.4}");
    assert!(auto.abs() < 0.0025, "default stride: {auto:+.4}");
    // The test has power: a sparse cache's difference is visible at this size.
    assert!(sparse.abs() > 0.01, "stride 64: {sparse:+.4}");
}
