//! The default scene against independent references (Mitsuba 3 path tracer,
//! shared/refs/), scored with the refs' metric, at a cost CI can pay.
//!
//! Bounds, and why (measurements in notes/accuracy.md):
//! * mean radiance within 2% and the caustic window's mean within 5%: the
//!   issue's bias requirement; we measure about 0.1% and 1% here;
//! * RMSE: 200² at 4 spp with 2e5 photons measured 0.0066 to 0.0072 over
//!   five seeds (the references' own noise is 0.0005); the bound 0.010
//!   leaves ~40% headroom for noise yet fails if, say, the caustic moves by a
//!   pixel or indirect light loses 5% (each measured to push RMSE past 0.012).

mod common;
use common::*;
use photonmap::scene::{Eye, Scene};

const RMSE_BOUND: f64 = 0.010;
const CAUSTIC_RMSE_BOUND: f64 = 0.06;

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
