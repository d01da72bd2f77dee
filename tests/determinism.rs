//! The same seed gives a bit-identical image whatever the number of threads;
//! another seed gives another image.

mod common;
use common::*;
use photonmap::scene::{Eye, Scene};

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
