//! Skipping what a scene does not need changes nothing but the time: each
//! skip renders the same image with the skip forced off.

use photonmap::film::Film;
use photonmap::light::{AreaLight, Emitting, Light};
use photonmap::material::Material;
use photonmap::metrics::compare;
use photonmap::photon::map::{PhotonMap, Scratch};
use photonmap::photon::trace::{trace_pass, Pass};
use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::scene::{Eye, Scene, SceneParts};
use photonmap::settings::Settings;
use photonmap::stats::Stats;

fn settings(skip: bool) -> Settings {
    Settings { photons: 50_000, caustic_photons: 50_000, width: 64, height: 64, skip, ..Settings::default() }
}

fn both_ways(parts: SceneParts) -> ((Film, Stats), (Film, Stats)) {
    let scene = Scene::from_parts(parts);
    (render(&scene, &settings(true), Mode::Quiet), render(&scene, &settings(false), Mode::Quiet))
}

/// Asserts that `a` and `b` differ by no more than renders of the same
/// scene with other seeds do: the RMSE within 1.2x theirs, and the means
/// within 3 standard deviations of the difference of two renders' means
/// (estimated from four other seeds), or 1%.
///
/// (Not 3x the difference to one other seed: in the noisy scene with the
/// light facing the ceiling one such difference can be 0.1% while the means
/// spread by 25% from seed to seed.)
fn same_within_noise(scene: &Scene, a: &Film, b: &Film, label: &str) {
    same_within_noise_of(scene, &settings(false), a, b, label)
}

/// [`same_within_noise`], with the other seeds rendered at `base`.
fn same_within_noise_of(scene: &Scene, base: &Settings, a: &Film, b: &Film, label: &str) {
    let others: Vec<Film> = (2..6).map(|seed| render(scene, &Settings { seed, ..*base }, Mode::Quiet).0).collect();
    let diff = compare(a, b).unwrap();
    let noise = others.iter().map(|o| compare(o, b).unwrap().rmse).sum::<f64>() / others.len() as f64;
    let means: Vec<f64> = others.iter().map(Film::mean).chain([b.mean()]).collect();
    let mean = means.iter().sum::<f64>() / means.len() as f64;
    let sd = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (means.len() - 1) as f64).sqrt();
    let allowed = (3.0 * std::f64::consts::SQRT_2 * sd).max(0.01 * b.mean());
    eprintln!(
        "{label}: rmse {:.5} vs seed noise {noise:.5}; means {:.5} {:.5}, seed-to-seed sd {sd:.5}",
        diff.rmse,
        a.mean(),
        b.mean()
    );
    assert!(diff.rmse <= 1.2 * noise, "{label}: rmse {} vs noise {noise}", diff.rmse);
    assert!((a.mean() - b.mean()).abs() <= allowed, "{label}: means {} {} (allowed {allowed})", a.mean(), b.mean());
}

#[test]
fn a_black_room_needs_no_photon_maps() {
    let mut parts = Scene::tncg15_parts(Eye::One);
    for m in &mut parts.materials {
        if let Material::Lambertian { rho } = m {
            *rho = photonmap::math::Color::ZERO;
        }
    }
    let ((on, s_on), (off, s_off)) = both_ways(parts);
    assert!(s_on.skipped_global && s_on.skipped_caustic);
    assert!(!s_off.skipped_global && !s_off.skipped_caustic && s_off.photon_rays > 0);
    assert_eq!(s_on.photon_rays, 0);
    // Nothing diffuse reflects, so both ways give the very same image: the
    // light, seen directly and in the mirror and the glass.
    assert!(on == off, "images differ");
    assert!(on.mean() > 0.0);
}

#[test]
fn a_room_without_mirror_or_glass_needs_no_caustic_map() {
    let mut parts = Scene::tncg15_parts(Eye::One);
    let specular: Vec<usize> = parts
        .prims
        .iter()
        .enumerate()
        .filter(|(_, p)| parts.materials[p.material as usize].is_specular())
        .map(|(i, _)| i)
        .collect();
    for i in specular.into_iter().rev() {
        parts.prims.remove(i);
    }
    let scene = Scene::from_parts(parts.clone());
    let ((on, s_on), (off, s_off)) = both_ways(parts);
    assert!(s_on.skipped_caustic && !s_on.skipped_global && !s_off.skipped_caustic);
    same_within_noise(&scene, &on, &off, "no mirror or glass");
}

/// The default light is a one-sided disk 0.001 below the ceiling: ceiling
/// points see only its back. Flipped to face up, it lights only the ceiling.
#[test]
fn lights_facing_away_get_no_shadow_rays() {
    for flip in [false, true] {
        let mut parts = Scene::tncg15_parts(Eye::One);
        if flip {
            let Light::Area(AreaLight { surface: Emitting::Disk(disk), .. }) = &mut parts.lights[0] else { panic!() };
            disk.normal = -disk.normal;
        }
        let scene = Scene::from_parts(parts);
        let (on, s_on) = render(&scene, &settings(true), Mode::Quiet);
        let (off, s_off) = render(&scene, &settings(false), Mode::Quiet);
        assert!(s_on.camera.shadow_rays_skipped > 0 && s_off.camera.shadow_rays_skipped == 0);
        // No ray was ever cast for a sample with cos_l <= 0; the skip saves
        // choosing the samples, and the rays cast stay the same in count.
        assert!(s_on.camera.rays.abs_diff(s_off.camera.rays) < s_off.camera.rays / 50);
        // Skipped samples draw no random numbers, so the images differ by noise only.
        same_within_noise(&scene, &on, &off, if flip { "light facing up" } else { "ceiling behind the light" });
    }
}

/// A pixel's later camera samples reuse its last caustic estimate where
/// they land on the same surface within a quarter of that estimate's
/// radius: the same paths and the same image within noise, with a fraction
/// of the estimates.
#[test]
fn a_pixels_samples_share_their_caustic_estimate() {
    let scene = Scene::tncg15(Eye::One);
    // Pixels small enough for a pixel's samples to land within reach (the
    // gather rays play no part in it).
    let with = Settings { width: 400, height: 400, gather_rays: 1, ..settings(true) };
    let without = Settings { caustic_reuse: 0.0, ..with };
    let (on, s_on) = render(&scene, &with, Mode::Quiet);
    let (off, s_off) = render(&scene, &without, Mode::Quiet);
    eprintln!(
        "caustic estimates {} + {} reused, without reuse {}",
        s_on.camera.caustic_estimates, s_on.camera.caustic_reused, s_off.camera.caustic_estimates
    );
    assert_eq!(s_off.camera.caustic_reused, 0);
    // Reusing draws no random numbers: every sample follows the same path
    // and asks for a caustic estimate at the same points.
    assert_eq!(s_on.camera.caustic_estimates + s_on.camera.caustic_reused, s_off.camera.caustic_estimates);
    assert_eq!(s_on.camera.rays, s_off.camera.rays);
    // 37% at this size (50% at the default 800 x 800 and 1e6 photons).
    assert!(4 * s_on.camera.caustic_reused > s_off.camera.caustic_estimates, "{s_on:?}");
    same_within_noise_of(&scene, &without, &on, &off, "caustic reuse");
    // Tighter than noise: an estimate moves by less than a pixel, on the
    // same surface (0.0015 of the seed-to-seed RMSE here; reusing across
    // surfaces and at 10x the reach measured 0.11).
    let noise = compare(&render(&scene, &Settings { seed: 2, ..without }, Mode::Quiet).0, &off).unwrap().rmse;
    let diff = compare(&on, &off).unwrap().rmse;
    assert!(diff < 0.02 * noise, "rmse {diff} with and without reuse, {noise} between seeds");
}

/// Caustic lookups where the map holds no photon within the radius cap are
/// answered by the map's grid without the kd-tree (a glass ball on a wide
/// floor under the sun, scenes/glass-sun.toml). Every estimate is the same
/// bit for bit with the grid and without it (the tree alone).
#[test]
fn caustic_lookups_where_the_map_is_empty_skip_the_tree() {
    let (scene, points) = glass_sun_and_floor_points();
    let photons = trace_pass(&scene, Pass::Caustic, 100_000, 1, &|_| {}).photons;
    let r = Settings::default().r_caustic(scene.diagonal());
    let with = PhotonMap::build_with_grid(photons.clone(), Some(r));
    let without = PhotonMap::build_with_grid(photons, Some(r)).without_grid();
    let (mut a, mut b) = (Scratch::default(), Scratch::default());
    let (mut empty, mut rejected) = (0, 0);
    for &(x, n) in &points {
        rejected += with.certainly_empty(x, r) as usize;
        let ea = with.radiance_cone(x, n, glam::Vec3::splat(0.8), 100, r, &mut a);
        let eb = without.radiance_cone(x, n, glam::Vec3::splat(0.8), 100, r, &mut b);
        assert_eq!(ea, eb, "at {x}");
        empty += (ea == glam::Vec3::ZERO) as usize;
    }
    eprintln!("{} lookups: {empty} find nothing, {rejected} rejected by the grid", points.len());
    // Light the ball reflects and scatters still reaches most of the floor
    // thinly, so few lookups are empty; the grid catches part of those (the
    // rest hold photons on another surface, or in a neighbouring cell).
    assert!(rejected > 0 && rejected <= empty, "{rejected} of {empty}");
}

/// scenes/glass-sun.toml and the first hits of its camera rays (64 x 48)
/// on the floor.
pub fn glass_sun_and_floor_points() -> (Scene, Vec<(glam::Vec3, glam::Vec3)>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/glass-sun.toml");
    let scene = Scene::from_parts(photonmap::scene::file::load(&path).unwrap().parts);
    let points = scene.diffuse_hits(64, 48);
    (scene, points)
}
