//! The error estimate against an answer known exactly, and `--target-error`.
//!
//! A Lambertian floor under a disk light, nothing else: each pixel's
//! radiance is rho / pi times the disk's irradiance, in closed form. After
//! 16 passes the per-pixel error estimate (the EXR's `error` layer) should
//! cover the true error at the confidence it states: |error| <= 1.96 sigma
//! in about 95% of the pixels (a little less: sigma is itself estimated
//! from 16 passes).

use glam::{Vec2, Vec3};
use photonmap::film::accumulation::Accumulation;
use photonmap::metrics::Window;
use photonmap::render::error_estimate::ErrorEstimate;

use photonmap::render::{render_passes, Budget, Stopped};
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};
use std::f64::consts::PI;
use std::ops::ControlFlow;
use std::path::Path;

const H: f64 = 2.0;
const R: f64 = 0.5;
const L: f64 = 10.0;
const RHO: f64 = 0.5;

const FLOOR: &str = r#"
[camera]
eye = [0, 0, 1]
target = [0, 0, 0]
up = [0, 1, 0]
vfov = 60
width = 40
height = 40

[materials.floor]
type = "lambertian"
rho = [0.5, 0.5, 0.5]

[[shapes]]
type = "quad"
vertices = [[-50, -50, 0], [50, -50, 0], [50, 50, 0], [-50, 50, 0]]
material = "floor"

[[lights]]
type = "disk"
center = [0.6, 0.0, 2.0]
normal = [0, 0, -1]
radius = 0.5
radiance = [10, 10, 10]
"#;

/// Irradiance at horizontal distance `rho` from the axis of a Lambertian
/// disk (radiance L, radius R) parallel to the plane at height H.
fn disk_irradiance(rho: f64) -> f64 {
    let (h2, r2, p2) = (H * H, R * R, rho * rho);
    PI * L / 2.0 * (1.0 - (h2 + p2 - r2) / ((h2 + p2 + r2).powi(2) - 4.0 * r2 * p2).sqrt())
}

fn coverage(method: Method) -> (f64, f64) {
    let file = photonmap::scene::file::parse(FLOOR, Path::new("floor.toml")).unwrap();
    let scene = Scene::from_parts(file.parts);
    let settings =
        Settings { method, photons: 20_000, caustic_photons: 0, spp: 1, width: 40, height: 40, ..Settings::default() };
    let run = render_passes(&scene, &settings, Accumulation::new(40, 40), 0, &Budget::passes(16), |_| {
        ControlFlow::Continue(())
    });
    let est = ErrorEstimate::new(&run.accumulation, settings.method.bias(settings.alpha))
        .expect("16 passes give an estimate");
    // What the EXR's `error` layer holds.
    let stated = est.error_film();
    let (mut covered, mut total, mut z2) = (0, 0, 0.0);
    for row in 0..40 {
        for col in 0..40 {
            let ray = scene.camera.ray(col, row, Vec2::splat(0.5));
            let p = ray.origin + ray.dir * (-ray.origin.z / ray.dir.z);
            let truth = RHO / PI * disk_irradiance((p - Vec3::new(0.6, 0.0, 0.0)).truncate().length() as f64);
            let i = (row * 40 + col) as usize;
            let sigma = stated.pixels[i].x as f64;
            let err = est.mean[i][0] - truth;
            total += 1;
            covered += (err.abs() <= 1.96 * sigma) as u32;
            z2 += (err / sigma).powi(2);
        }
    }
    (covered as f64 / total as f64, (z2 / total as f64).sqrt())
}

#[test]
fn the_per_pixel_error_covers_the_true_error_at_its_confidence() {
    for method in [Method::Path, Method::Photon] {
        let (fraction, rms_z) = coverage(method);
        eprintln!(
            "{method:?}: |error| <= 1.96 sigma in {:.1}% of pixels; RMS of error / sigma {rms_z:.3}",
            100.0 * fraction
        );
        assert!((0.90..=0.99).contains(&fraction), "{method:?}: covered in {:.1}% of pixels", 100.0 * fraction);
        assert!((0.8..=1.25).contains(&rms_z), "{method:?}: error / sigma has RMS {rms_z}");
    }
}

/// A looser target stops sooner, and each stop is at its target.
#[test]
fn a_looser_target_error_stops_sooner() {
    let scene = Scene::tncg15(photonmap::scene::Eye::One);
    let settings =
        Settings { photons: 3_000, caustic_photons: 3_000, spp: 1, width: 32, height: 32, ..Settings::default() };
    let window = Window { name: "all".into(), rows: (0, 32), cols: (0, 32) };
    let stop = |target: f64| {
        let budget =
            Budget { end: Some(500), target_error: Some(target), windows: vec![window.clone()], ..Budget::default() };
        let run =
            render_passes(&scene, &settings, Accumulation::new(32, 32), 0, &budget, |_| ControlFlow::Continue(()));
        assert_eq!(run.stopped, Stopped::TargetError, "target {target}");
        let reached = run.predictions[1].1.relative_rmse();
        assert!(reached < target, "stopped at {reached} for target {target}");
        run.accumulation.passes.count()
    };
    let (loose, tight) = (stop(0.12), stop(0.06));
    assert!(loose >= 4 && loose < tight, "passes: {loose} for 12%, {tight} for 6%");
}
