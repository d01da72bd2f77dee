//! Adaptive camera samples (render::adaptive): the counts come from pass
//! 0's pilot and are the same on any number of threads; passes rendered
//! apart (a range not starting at 0) take the counts one process takes,
//! so their sums add up to its image bit for bit; and the image's mean is
//! the true one (a path-traced render against the reference, within its
//! noise).

mod common;
use common::*;
use photonmap::film::accumulation::Accumulation;
use photonmap::film::Film;
use photonmap::metrics::compare;
use photonmap::render::{render_passes, render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings};
use std::ops::ControlFlow;

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

fn small() -> Settings {
    Settings {
        photons: 10_000,
        caustic_photons: 10_000,
        spp: 1,
        width: 48,
        height: 48,
        adaptive: true,
        ..Settings::default()
    }
}

/// The glass ball and the caustic take more samples, the same wherever
/// the rows ran; without adaptive samples the image differs.
#[test]
fn adaptive_counts_are_thread_independent() {
    let scene = Scene::tncg15(Eye::One);
    let run = |settings: Settings| render_progressive(&scene, &settings, Budget::passes(3), |_| {});
    let (one, stats) = on_threads(1, || run(small()));
    assert!(stats.adaptive_pixels > 0 && stats.adaptive_pixels < 48 * 48 / 2, "{}", stats.adaptive_pixels);
    assert!(stats.adaptive_samples >= stats.adaptive_pixels as u64);
    for threads in [2, 3] {
        let (film, s) = on_threads(threads, || run(small()));
        assert_eq!(film, one, "{threads} threads");
        assert_eq!((s.adaptive_pixels, s.adaptive_samples), (stats.adaptive_pixels, stats.adaptive_samples));
    }
    let (even, s) = on_threads(2, || run(Settings { adaptive: false, ..small() }));
    assert_eq!(s.adaptive_pixels, 0);
    assert_ne!(even, one);
}

/// Passes 0..2 and 2..5 rendered apart (the second renders pass 0 for its
/// pilot alone) add up to the sums of passes 0..5 rendered at once.
#[test]
fn ranges_rendered_apart_add_up_to_one_render() {
    let scene = Scene::tncg15(Eye::One);
    let settings = small();
    let range = |first: u32, end: u32| {
        let acc = Accumulation::new(settings.width, settings.height);
        let budget = Budget { end: Some(end), ..Budget::default() };
        render_passes(&scene, &settings, acc, first, &budget, |_| ControlFlow::Continue(()))
    };
    let whole = range(0, 5);
    assert!(whole.stats.adaptive_pixels > 0);
    let (a, b) = (range(0, 2), range(2, 5));
    assert_eq!(b.stats.adaptive_pixels, whole.stats.adaptive_pixels);
    let mut merged = a.accumulation.clone();
    merged.merge(&b.accumulation).unwrap();
    let bits = |f: &Film| f.pixels.iter().flat_map(|c| c.to_array()).map(f32::to_bits).collect::<Vec<_>>();
    assert_eq!(bits(&merged.average()), bits(&whole.film()));
}

/// Student's t-test, as tests/progressive.rs's for the path tracer: 8
/// independent progressive path-traced renders (4 passes of 1 spp, 200²,
/// adaptive); their whole-image and caustic-window means must agree with
/// the reference's within 5.41 standard errors (two-sided 99.9%, 7 degrees
/// of freedom). A count that read a pass's own samples (more samples where
/// they came out bright) would move the mean.
#[test]
fn adaptive_path_tracing_agrees_with_the_reference_within_noise() {
    let scene = Scene::tncg15(Eye::One);
    let reference = reference("default_e1_200.exr");
    let runs: Vec<(f64, f64)> = (0..8)
        .map(|seed| {
            let s = Settings {
                method: Method::Path,
                spp: 1,
                width: 200,
                height: 200,
                seed,
                adaptive: true,
                ..Settings::default()
            };
            let (film, stats) = render_progressive(&scene, &s, Budget::passes(4), |_| {});
            assert!(stats.adaptive_pixels > 0);
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
        assert!(se / truth < [0.005, 0.05][which], "se {se}");
    }
}
