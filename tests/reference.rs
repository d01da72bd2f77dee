//! The default scene against independent references (Mitsuba 3 path tracer,
//! shared/refs/), scored with the refs' metric, at a cost CI can pay.
//!
//! Bounds, and why (measurements in notes/accuracy.md):
//! * mean radiance within 2% and the caustic window's mean within 5%: the
//!   issue's bias requirement; five seeds measured within 0.28% and 0.9%;
//! * RMSE: this CI-sized render (200² at 4 spp, 2e5 + 2e5 photons, 8 gather
//!   rays) measured 0.0082 to 0.0094 over seeds 1-5 (caustic window 0.035 to
//!   0.049); the references' own noise is 0.0005 (eye 1) and 0.0023 (eye 2).
//!   The bounds 0.012 and 0.065 sit about 25% above the worst seed.

mod common;
use common::*;
use photonmap::scene::{Eye, Scene};

const RMSE_BOUND: f64 = 0.012;
const CAUSTIC_RMSE_BOUND: f64 = 0.065;

fn check(eye: Eye, reference_name: &str, label: &str) {
    let scene = Scene::tncg15(eye);
    let film = render_quiet(&scene, &ci_settings(200));
    let reference = reference(reference_name);
    let ok = |m: &photonmap::metrics::Metrics| {
        (m.mean_x / m.mean_r - 1.0).abs() < 0.02
            && (m.caustic_mean_x / m.caustic_mean_r - 1.0).abs() < 0.05
            && m.rmse < RMSE_BOUND
            && m.caustic_rmse < CAUSTIC_RMSE_BOUND
            && m.nan_count == 0
    };
    let m = score_or_leave_evidence(label, &film, &reference, ok);
    eprintln!("{label}: {m:?}");
    assert_eq!(m.nan_count, 0);
    assert!((m.mean_x / m.mean_r - 1.0).abs() < 0.02, "mean {} vs reference {}", m.mean_x, m.mean_r);
    assert!(
        (m.caustic_mean_x / m.caustic_mean_r - 1.0).abs() < 0.05,
        "caustic window mean {} vs reference {}",
        m.caustic_mean_x,
        m.caustic_mean_r
    );
    assert!(m.rmse < RMSE_BOUND, "rmse {} >= {RMSE_BOUND}", m.rmse);
    assert!(m.caustic_rmse < CAUSTIC_RMSE_BOUND, "caustic rmse {} >= {CAUSTIC_RMSE_BOUND}", m.caustic_rmse);
}

#[test]
fn eye_one_matches_the_independent_reference() {
    check(Eye::One, "default_e1_200.exr", "reference-eye1");
}

/// Eye 2 (90 degree view) against a Mitsuba 3 reference rendered for this
/// view (notes/tools/mitsuba_reference.py, 8192 spp at 200², noise about
/// 0.0025: the bounds above hold with that added).
#[test]
fn eye_two_matches_its_independent_reference() {
    check(Eye::Two, "default_e2_200.exr", "reference-eye2");
}
