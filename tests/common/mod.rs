//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod chi2;
pub mod material_chi2;

use photonmap::film::Film;
use photonmap::metrics::{compare, Metrics};
use photonmap::output::{read_exr, write};
use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::scene::Scene;
use photonmap::settings::Settings;
use std::path::{Path, PathBuf};

pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("data").join(name)
}

pub fn reference(name: &str) -> Film {
    read_exr(&data(name)).expect("reference image in tests/data")
}

/// Settings a CI machine (2 cores) renders in a few seconds.
pub fn ci_settings(size: u32) -> Settings {
    Settings {
        photons: 200_000,
        caustic_photons: 200_000,
        spp: 4,
        gather_rays: 8,
        width: size,
        height: size,
        ..Settings::default()
    }
}

/// A scene of the suite (scenes/suite/), its meshes written first: its
/// manifest entry, the scene built, and its reference.
pub fn suite_scene(name: &str) -> (photonmap::suite::SuiteScene, Scene, Film) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    photonmap::scene::procedural::write_suite_meshes(&root.join("scenes/suite/meshes"), name == "07-million")
        .expect("the suite's meshes can be written");
    let suite = photonmap::suite::load(&root.join("scenes/suite")).expect("scenes/suite/suite.toml");
    let s = suite.into_iter().find(|s| s.name == name).expect("a scene of the suite");
    let reference = s.load_reference().expect("the scene's reference");
    let file = photonmap::scene::file::load(&s.scene).unwrap_or_else(|e| panic!("{e}"));
    (s, Scene::from_parts(file.parts), reference)
}

pub fn render_quiet(scene: &Scene, settings: &Settings) -> Film {
    let (film, stats) = render(scene, settings, Mode::Quiet);
    assert_eq!(stats.camera.nonfinite, 0, "non-finite samples: first at {:?}", stats.camera.first_nonfinite());
    film
}

/// Scores `film` against `reference`; when `ok` is false, leaves the got,
/// reference and difference images under target/test-artifacts/ and says where.
pub fn score_or_leave_evidence(name: &str, film: &Film, reference: &Film, ok: impl Fn(&Metrics) -> bool) -> Metrics {
    let m = compare(film, reference).expect("comparable sizes");
    if !ok(&m) {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target").join("test-artifacts");
        std::fs::create_dir_all(&dir).unwrap();
        let down = if film.width == reference.width {
            film.clone()
        } else {
            photonmap::metrics::box_down(film, film.width / reference.width)
        };
        let diff = Film {
            width: down.width,
            height: down.height,
            pixels: down.pixels.iter().zip(&reference.pixels).map(|(a, b)| (*a - *b).abs()).collect(),
        };
        for (suffix, img) in [("got", &down), ("reference", reference), ("diff", &diff)] {
            let path = dir.join(format!("{name}-{suffix}.exr"));
            write(&path, img, Default::default(), 1.0).unwrap();
            eprintln!("evidence: {}", path.display());
        }
    }
    m
}

/// Runs the `photonmap` binary with `args`.
pub fn photonmap(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_photonmap")).args(args).output().expect("run photonmap")
}

/// An empty directory of its own for test `name`.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
