//! A material's smooth samples against its pdf, and a family of such
//! cases run at one Šidák-corrected level (the harness: `chi2.rs`).
//! Specular branches (deltas, which no density describes) are left out:
//! the smooth lobes' pdf integrates to their chance, which the harness
//! checks too.

use super::chi2::{Chi2, Outcome};
use glam::Vec3;
use photonmap::material::{Lobe, Material, Transport};
use photonmap::sampling::{stream, Domain};

/// One material's test from `wo` on its `entering` side, with `chi2`'s
/// bins, sample count and number of tests sharing the level.
pub fn material_outcome(chi2: &Chi2, m: &Material, wo: Vec3, entering: bool, seed: u64) -> Outcome {
    let mut rng = stream(seed, Domain::Camera, 0);
    chi2.run(
        || {
            m.sample(wo, entering, Transport::Radiance, &mut rng)
                .filter(|s| s.lobe != Lobe::Specular)
                .map(|s| s.wi.normalize())
        },
        |wi| m.pdf(wo, wi, entering) as f64,
    )
}

/// Runs every case (seeds from `first_seed` on), and fails listing those
/// that fail.
pub fn check_all(family: &str, cases: Vec<(String, Material, Vec3, bool)>, samples: usize, first_seed: u64) {
    let chi2 = Chi2 { tests: cases.len(), samples, ..Chi2::default() };
    let mut failed = Vec::new();
    for (i, (name, m, wo, entering)) in cases.into_iter().enumerate() {
        let o = material_outcome(&chi2, &m, wo, entering, first_seed + i as u64);
        println!(
            "{family} {name} wo {wo:.2} entering {entering}: chi2 {:.1} dof {} p {:.4} (level {:.5}) pdf mass {:.4}",
            o.statistic, o.dof, o.p_value, o.threshold, o.pdf_mass
        );
        if !o.passed() {
            failed.push(format!("{name} wo {wo} entering {entering}: p {}", o.p_value));
        }
    }
    assert!(failed.is_empty(), "{family}: {failed:?}");
}
