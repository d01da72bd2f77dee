//! Every material's sampling against its pdf (χ², tests/common/chi2.rs),
//! over both distributions, isotropic and anisotropic roughness, several
//! roughnesses and incident angles, reflection and transmission, both
//! sides of glass; and the microfacet distributions' visible normals
//! against their density. Samples from specular branches (deltas, which
//! no density describes) are left out: the smooth lobes' pdf integrates to
//! the chance of a smooth lobe, and the harness checks that too.

mod common;

use common::chi2::{gamma_q, Chi2};
use glam::Vec3;
use photonmap::material::{Distribution, Material, Microfacet, Phong, Transport};
use photonmap::math::Color;
use photonmap::sampling::{next_2d, stream, Domain};

/// Incident directions: near normal, oblique, grazing (anisotropic lobes
/// are seen from an azimuth off both axes).
fn incidences() -> [Vec3; 3] {
    [
        Vec3::new(0.2, 0.1, 0.97).normalize(),
        Vec3::new(0.55, 0.35, 0.6).normalize(),
        Vec3::new(0.75, -0.6, 0.18).normalize(),
    ]
}

const DISTRIBUTIONS: [Distribution; 2] = [Distribution::Beckmann, Distribution::Ggx];
/// (alpha_u, alpha_v): smooth-ish, rough, anisotropic.
const ROUGHNESS: [(f32, f32); 3] = [(0.1, 0.1), (0.45, 0.45), (0.12, 0.5)];

/// Runs every case, and fails listing those that fail.
fn check_all(family: &str, cases: Vec<(String, Material, Vec3, bool)>) {
    common::material_chi2::check_all(family, cases, Chi2::default().samples, 1000);
}

#[test]
fn microfacet_visible_normals_follow_their_density() {
    let mut cases = Vec::new();
    for d in DISTRIBUTIONS {
        for (au, av) in ROUGHNESS {
            for wo in incidences() {
                cases.push((Microfacet::new(d, au, av), wo));
            }
        }
    }
    let n = cases.len();
    let mut failed = Vec::new();
    for (i, (mf, wo)) in cases.into_iter().enumerate() {
        let mut rng = stream(7, Domain::Camera, i as u64);
        let o = Chi2 { tests: n, ..Chi2::default() }
            .run(|| Some(mf.sample_visible(wo, next_2d(&mut rng))), |m| mf.visible_pdf(wo, m) as f64);
        println!("{mf:?} wo {wo:.2}: chi2 {:.1} dof {} p {:.4} mass {:.4}", o.statistic, o.dof, o.p_value, o.pdf_mass);
        if !o.passed() {
            failed.push(format!("{mf:?} {wo}: p {}", o.p_value));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

#[test]
fn rough_conductor_samples_follow_its_pdf() {
    let mut cases = Vec::new();
    for d in DISTRIBUTIONS {
        for (au, av) in ROUGHNESS {
            let m =
                Material::rough_conductor(d, au, av, Color::new(0.2, 0.9, 1.1), Color::new(3.9, 2.4, 2.2), Color::ONE);
            for wo in incidences() {
                cases.push((format!("{} {au}/{av}", d.name()), m, wo, true));
            }
        }
    }
    check_all("roughconductor", cases);
}

#[test]
fn rough_dielectric_samples_follow_its_pdf_both_ways_and_sides() {
    let mut cases = Vec::new();
    for d in DISTRIBUTIONS {
        for (au, av) in ROUGHNESS {
            let m = Material::rough_dielectric(d, au, av, 1.5, 1.0, Color::ONE, Color::ONE);
            for wo in incidences() {
                for entering in [true, false] {
                    cases.push((format!("{} {au}/{av}", d.name()), m, wo, entering));
                }
            }
        }
    }
    check_all("roughdielectric", cases);
}

/// The Phong material these tests sample, with mirror reflectance `mirror`.
fn phong(mirror: f32) -> Phong {
    Phong {
        color: Color::new(0.9, 0.6, 0.3),
        ambient: 0.0,
        diffuse: 0.4,
        specular: 0.3,
        metalness: 0.2,
        shininess: 20.0,
        mirror,
    }
}

#[test]
fn plastics_lambertian_and_phong_samples_follow_their_pdfs() {
    let mut cases = Vec::new();
    let phong = phong(0.2);
    let mut materials = vec![
        ("lambertian".to_string(), Material::Lambertian { rho: Color::new(0.8, 0.5, 0.2) }),
        ("phong".to_string(), Material::Phong(phong)),
        ("phong, no mirror".to_string(), Material::Phong(Phong { mirror: 0.0, ..phong })),
        ("plastic".to_string(), Material::plastic(Color::new(0.6, 0.3, 0.1), Color::ONE, 1.49, 1.0, false)),
    ];
    for d in DISTRIBUTIONS {
        for alpha in [0.1, 0.45] {
            let m = Material::rough_plastic(d, alpha, Color::new(0.6, 0.3, 0.1), Color::ONE, 1.49, 1.0, true);
            materials.push((format!("roughplastic {} {alpha}", d.name()), m));
        }
    }
    for (name, m) in materials {
        for wo in incidences() {
            cases.push((name.clone(), m, wo, true));
        }
    }
    check_all("diffuse and coated", cases);
}

/// A glossy lobe sampled at given points of the unit square (the camera
/// pass's stratified gather rays at a glossy vertex, `Glossy::sample_at`)
/// draws by the lobe's own pdf where the points are uniform: rough glass
/// from both sides, a rough metal, a rough plastic's coat, Phong's lobe.
#[test]
fn glossy_lobes_sampled_at_given_points_follow_their_pdf() {
    let phong = phong(0.0);
    let mut materials = vec![("phong".to_string(), Material::Phong(phong))];
    for d in DISTRIBUTIONS {
        for (au, av) in ROUGHNESS {
            let name = format!("{} {au}/{av}", d.name());
            materials.push((
                format!("roughdielectric {name}"),
                Material::rough_dielectric(d, au, av, 1.5, 1.0, Color::ONE, Color::ONE),
            ));
            materials.push((
                format!("roughconductor {name}"),
                Material::rough_conductor(d, au, av, Color::new(0.2, 0.9, 1.1), Color::new(3.9, 2.4, 2.2), Color::ONE),
            ));
        }
        materials.push((
            format!("roughplastic {}", d.name()),
            Material::rough_plastic(d, 0.2, Color::new(0.6, 0.3, 0.1), Color::ONE, 1.49, 1.0, true),
        ));
    }
    let mut cases = Vec::new();
    for (name, m) in &materials {
        for wo in incidences() {
            for entering in [true, false] {
                cases.push((name.clone(), *m, wo, entering));
            }
        }
    }
    let n = cases.len();
    let mut failed = Vec::new();
    for (i, (name, m, wo, entering)) in cases.into_iter().enumerate() {
        let g = m.glossy().expect("a glossy lobe");
        let mut rng = stream(17, Domain::Camera, i as u64);
        let mut choice = stream(18, Domain::Camera, i as u64);
        let o = Chi2 { tests: n, ..Chi2::default() }.run(
            || g.sample_at(wo, entering, Transport::Radiance, next_2d(&mut rng), &mut choice).map(|(wi, _)| wi),
            |wi| g.pdf(wo, wi, entering) as f64,
        );
        println!(
            "{name} wo {wo:.2} entering {entering}: chi2 {:.1} dof {} p {:.4} mass {:.4}",
            o.statistic, o.dof, o.p_value, o.pdf_mass
        );
        if !o.passed() {
            failed.push(format!("{name} {wo} {entering}: p {}", o.p_value));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

/// The harness has power: a cosine sampler tested against the uniform
/// hemisphere's pdf, and against its own pdf with a few percent of its
/// mass moved from one azimuth to another, fails; against the right pdf
/// it passes. And the p-value is the χ² tail (known values).
#[test]
fn the_harness_rejects_a_wrong_pdf() {
    let run = |pdf: &dyn Fn(Vec3) -> f64| {
        let mut rng = stream(3, Domain::Camera, 0);
        Chi2::default().run(|| Some(photonmap::sampling::cosine_hemisphere(next_2d(&mut rng))), pdf)
    };
    let cosine = |w: Vec3| (w.z.max(0.0) / std::f32::consts::PI) as f64;
    assert!(run(&cosine).passed());
    assert!(!run(&|w: Vec3| if w.z > 0.0 { 1.0 / (2.0 * std::f64::consts::PI) } else { 0.0 }).passed());
    let skewed = |w: Vec3| cosine(w) * (1.0 + 0.05 * w.x.signum() as f64);
    assert!(!run(&skewed).passed());
    // Q(k/2, x/2): the chance a χ² of k degrees exceeds x.
    assert!((gamma_q(0.5, 3.841 / 2.0) - 0.05).abs() < 1e-3);
    assert!((gamma_q(5.0, 18.307 / 2.0) - 0.05).abs() < 1e-3);
    assert!((gamma_q(50.0, 124.342 / 2.0) - 0.05).abs() < 1e-3);
}
