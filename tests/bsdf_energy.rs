//! The new materials' energy and symmetry: a sample's weight is f |cos| /
//! pdf by the material's own eval and pdf; white furnaces (the mean weight
//! of a material's samples, specular branches included, is what it
//! reflects and transmits: 1 where the model conserves energy, less by
//! Smith's single-scattering loss where it does not); reciprocity.

use glam::Vec3;
use photonmap::material::{Distribution, Lobe, Material, Transport};
use photonmap::math::Color;
use photonmap::sampling::{next_2d, stream, uniform_cone, Domain};
use std::f32::consts::PI;

const DISTRIBUTIONS: [Distribution; 2] = [Distribution::Beckmann, Distribution::Ggx];

fn incidences() -> [Vec3; 3] {
    [
        Vec3::new(0.1, 0.05, 0.99).normalize(),
        Vec3::new(0.55, 0.35, 0.6).normalize(),
        Vec3::new(0.75, -0.6, 0.2).normalize(),
    ]
}

fn white_conductor(d: Distribution, au: f32, av: f32) -> Material {
    Material::rough_conductor(d, au, av, Color::ZERO, Color::ONE, Color::ONE)
}

fn glass(d: Distribution, au: f32, av: f32) -> Material {
    Material::rough_dielectric(d, au, av, 1.5, 1.0, Color::ONE, Color::ONE)
}

fn new_materials() -> Vec<(String, Material)> {
    let mut v = vec![
        ("conductor".into(), Material::conductor(Color::new(0.2, 0.9, 1.1), Color::new(3.9, 2.4, 2.2), Color::ONE)),
        ("thindielectric".into(), Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE)),
        ("plastic".into(), Material::plastic(Color::new(0.6, 0.3, 0.1), Color::ONE, 1.49, 1.0, false)),
        ("plastic nonlinear".into(), Material::plastic(Color::new(0.6, 0.3, 0.1), Color::splat(0.8), 1.49, 1.0, true)),
    ];
    for d in DISTRIBUTIONS {
        for (au, av) in [(0.1, 0.1), (0.5, 0.5), (0.1, 0.4)] {
            let n = |kind: &str| format!("{kind} {} {au}/{av}", d.name());
            v.push((
                n("roughconductor"),
                Material::rough_conductor(d, au, av, Color::new(0.2, 0.9, 1.1), Color::new(3.9, 2.4, 2.2), Color::ONE),
            ));
            v.push((n("roughdielectric"), glass(d, au, av)));
        }
        for alpha in [0.1, 0.5] {
            let m = Material::rough_plastic(d, alpha, Color::new(0.6, 0.3, 0.1), Color::ONE, 1.49, 1.0, false);
            v.push((format!("roughplastic {} {alpha}", d.name()), m));
        }
    }
    v
}

/// The mean weight of `n` samples from `wo` (everything the material sends on).
fn albedo(m: &Material, wo: Vec3, entering: bool, mode: Transport, n: usize, seed: u64) -> Color {
    let mut rng = stream(seed, Domain::Camera, 0);
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..n {
        if let Some(s) = m.sample(wo, entering, mode, &mut rng) {
            sum += s.weight.as_dvec3();
        }
    }
    (sum / n as f64).as_vec3()
}

/// For every new material, both sides and both transports, a smooth
/// sample's weight is eval |cos| / pdf to 1e-3.
#[test]
fn sample_weights_are_f_cos_over_pdf() {
    let mut rng = stream(5, Domain::Camera, 0);
    for (name, m) in new_materials() {
        let mut checked = 0;
        for wo in incidences() {
            for entering in [true, false] {
                for mode in [Transport::Radiance, Transport::Importance] {
                    for _ in 0..3000 {
                        let Some(s) = m.sample(wo, entering, mode, &mut rng) else { continue };
                        if s.lobe == Lobe::Specular {
                            continue;
                        }
                        let pdf = m.pdf(wo, s.wi, entering);
                        assert!(pdf > 0.0, "{name}: a sample where the pdf is 0: {s:?}");
                        let want = m.eval(wo, s.wi, entering, mode) * s.wi.z.abs() / pdf;
                        let err = (s.weight - want).abs().max_element();
                        assert!(err <= 1e-3 * want.max_element().max(1e-3), "{name} wo {wo}: {s:?} vs {want}");
                        checked += 1;
                    }
                }
            }
        }
        let smooth = !matches!(m, Material::Conductor(_) | Material::ThinDielectric(_));
        assert!(!smooth || checked > 5000, "{name}: {checked} smooth samples");
    }
}

/// The sampled albedo equals the albedo integrated independently (the
/// smooth lobes' f |cos| over uniform directions of the whole sphere, plus
/// the specular branches' shares), within 1.5%.
#[test]
fn sampled_albedo_matches_the_integrated_one() {
    for (name, m) in new_materials() {
        for wo in incidences() {
            for entering in [true, false] {
                let n = 400_000;
                let got = albedo(&m, wo, entering, Transport::Importance, n, 9);
                let mut rng = stream(10, Domain::Camera, 0);
                let mut smooth = glam::DVec3::ZERO;
                for _ in 0..n {
                    let wi = uniform_cone(next_2d(&mut rng), -1.0);
                    smooth += (m.eval(wo, wi, entering, Transport::Importance) * wi.z.abs() * 4.0 * PI).as_dvec3();
                }
                let branches: Color =
                    m.specular_branches(wo, entering, Transport::Importance).iter().map(|b| b.prob * b.scale).sum();
                let want = (smooth / n as f64).as_vec3() + branches;
                let err = (got - want).abs().max_element();
                // Uniform directions find a sharp lobe's integral noisily.
                assert!(err < 0.015 + 0.03 * want.max_element(), "{name} wo {wo} entering {entering}: {got} vs {want}");
            }
        }
    }
}

/// White furnaces. Smooth metal of eta 0, k 1, thin glass and a white
/// plastic reflect (and pass) everything; a white rough metal and rough
/// glass lose only Smith's single-scattering share, which is nothing as
/// alpha goes to 0 and grows with alpha and at grazing incidence; never
/// more than 1.
#[test]
fn white_furnaces() {
    let n = 400_000;
    let close = |got: f32, want: f32, tol: f32, what: &str| {
        assert!((got - want).abs() <= tol, "{what}: {got} vs {want}");
    };
    for wo in incidences() {
        let mirror = Material::conductor(Color::ZERO, Color::ONE, Color::ONE);
        close(albedo(&mirror, wo, true, Transport::Radiance, 1000, 1).x, 1.0, 1e-6, "conductor eta 0 k 1");
        for entering in [true, false] {
            let thin = Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE);
            close(albedo(&thin, wo, entering, Transport::Radiance, n, 2).x, 1.0, 1e-3, "thindielectric");
        }
        for nonlinear in [false, true] {
            let white = Material::plastic(Color::ONE, Color::ONE, 1.49, 1.0, nonlinear);
            // The fits of the diffuse Fresnel reflectance are within 0.1%.
            let a = albedo(&white, wo, true, Transport::Radiance, n, 3).x;
            println!("white plastic nonlinear {nonlinear} wo.z {:.2}: {a:.4}", wo.z);
            close(a, 1.0, 0.01, "white plastic");
        }
    }
    for d in DISTRIBUTIONS {
        for (au, av) in [(0.02, 0.02), (0.1, 0.1), (0.3, 0.3), (0.6, 0.6), (1.0, 1.0), (0.1, 0.5)] {
            for wo in incidences() {
                let metal = albedo(&white_conductor(d, au, av), wo, true, Transport::Radiance, n, 4).x;
                let outside = albedo(&glass(d, au, av), wo, true, Transport::Importance, n, 5).x;
                let inside = albedo(&glass(d, au, av), wo, false, Transport::Importance, n, 6).x;
                println!(
                    "{} alpha {au}/{av} wo.z {:.2}: white metal {metal:.4}, rough glass from outside {outside:.4}, from inside {inside:.4}",
                    d.name(),
                    wo.z
                );
                for (what, a) in [("metal", metal), ("glass outside", outside), ("glass inside", inside)] {
                    assert!(a <= 1.0 + 3e-3, "{what} {au}: {a} over 1");
                    // At alpha 0.1 and below Smith's model loses under 3.5% (GGX's longer tails and glass seen from inside the more) except at grazing incidence.
                    if au.max(av) <= 0.1 && wo.z > 0.5 {
                        assert!(a > 0.965, "{what} {} {au}/{av} wo.z {}: {a}", d.name(), wo.z);
                    }
                    // At alpha 1, seen from above, a white metal keeps
                    // 0.31 (GGX) to 0.47 (Beckmann): normals tilted past
                    // 45° reflect below the horizon.
                    assert!(a > 0.3, "{what} {} {au}/{av}: {a}", d.name());
                }
            }
        }
    }
}

/// A closed form: GGX of alpha 1 is the cosine distribution of normals
/// (D = 1 / pi), so from the normal a white metal reflects the normals
/// within 45°, each masked by G1 = 2 cos 2t / (1 + cos 2t): its albedo is
/// the integral of u / (1 + u) over [0, 1], 1 - ln 2 = 0.3069.
#[test]
fn white_ggx_metal_of_alpha_one_keeps_one_minus_ln_2() {
    let a = albedo(&white_conductor(Distribution::Ggx, 1.0, 1.0), Vec3::Z, true, Transport::Radiance, 1_000_000, 12).x;
    assert!((a - (1.0 - 2f32.ln())).abs() < 2e-3, "{a}");
}

/// Reciprocity: reflection is symmetric in its two directions; light
/// crossing rough glass obeys f_importance(wo -> wi) = f_radiance of the
/// reversed path (Veach 1997, eq. 5.14, with Mitsuba's radiance scale);
/// to 1%: a sharp lobe's D magnifies the rounding of the half vector.
#[test]
fn reciprocity() {
    let mut rng = stream(8, Domain::Camera, 0);
    let flip = |v: Vec3| Vec3::new(v.x, v.y, -v.z);
    for (name, m) in new_materials() {
        let mut checked = 0;
        for _ in 0..20_000 {
            let wo = uniform_cone(next_2d(&mut rng), 0.0);
            let wi = uniform_cone(next_2d(&mut rng), -1.0);
            let entering = wi.x > 0.0;
            if wi.z < 0.0 {
                // Leave out microfacets met within cos 0.02 of grazing: seen
                // from the other side they lie within 2e-4 of the critical
                // angle, where Fresnel's 1 - sin^2 cancels f32's digits.
                let eta = if entering { 1.5 } else { 1.0 / 1.5 };
                let h = (wo + eta * wi).normalize();
                if wo.dot(h).abs() < 0.02 || wi.dot(h).abs() < 0.02 {
                    continue;
                }
            }
            let f = m.eval(wo, wi, entering, Transport::Importance);
            let back = if wi.z > 0.0 {
                m.eval(wi, wo, entering, Transport::Importance)
            } else {
                m.eval(flip(wi), flip(wo), !entering, Transport::Radiance)
            };
            let scale = f.max_element().max(back.max_element());
            if scale < 1e-6 {
                continue;
            }
            assert!((f - back).abs().max_element() <= 1e-2 * scale, "{name}: {wo} {wi} {entering}: {f} vs {back}");
            checked += 1;
        }
        let smooth = !matches!(m, Material::Conductor(_) | Material::ThinDielectric(_));
        assert!(!smooth || checked > 500, "{name}: {checked}");
    }
}

/// What photon mapping asks: metals and thin glass are specular; rough
/// lobes are glossy, carrying caustics below alpha 0.3; plastics store
/// photons and their coat is specular (smooth) or glossy (rough).
#[test]
fn what_photon_mapping_asks_of_the_new_materials() {
    let conductor = Material::conductor(Color::ZERO, Color::ONE, Color::ONE);
    assert!(conductor.is_specular() && conductor.diffuse_rho().is_none() && conductor.glossy().is_none());
    let thin = Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE);
    assert!(thin.is_specular() && thin.has_specular_lobe());
    let frosted = glass(Distribution::Ggx, 0.1, 0.1);
    assert!(frosted.glossy().is_some_and(|g| g.carries_caustics() && g.transmits()) && frosted.has_specular_lobe());
    assert!(frosted.transmits() && frosted.diffuse_rho().is_none() && !frosted.is_specular());
    let rough = white_conductor(Distribution::Beckmann, 0.1, 0.6);
    assert!(rough.glossy().is_some_and(|g| !g.carries_caustics()) && !rough.has_specular_lobe());
    let plastic = Material::plastic(Color::splat(0.5), Color::ONE, 1.49, 1.0, false);
    assert!(plastic.diffuse_rho().is_some() && plastic.has_specular_lobe() && plastic.glossy().is_none());
    // Light arriving evenly: the diffuse albedo towards the normal is
    // (1 - F(0°)) rho, F(0°) = (0.49 / 2.49)^2 (exactly, but for the fits
    // of the diffuse Fresnel reflectances: 1 - F_dr,ext = eta^2 (1 - F_dr,int)).
    let a = plastic.diffuse_albedo(Vec3::Z).x;
    assert!((a - (1.0 - (0.49f32 / 2.49).powi(2)) * 0.5).abs() < 0.003, "{a}");
    let rp = Material::rough_plastic(Distribution::Ggx, 0.2, Color::splat(0.5), Color::ONE, 1.49, 1.0, false);
    assert!(rp.diffuse_rho().is_some() && rp.glossy().is_some_and(|g| g.carries_caustics()));
    // A photon on a plastic goes on with about what it reflects.
    let p = plastic.photon_survival(Vec3::Z);
    assert!(p > 0.5 && p < 0.6, "{p}");
}
