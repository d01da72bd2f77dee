//! Mitsuba's principled and thin principled BSDFs: sampling against the
//! pdf (χ², tests/common/chi2.rs), for the whole BSDF and for the glossy
//! lobes photon mapping samples alone, over parameter sets that turn each
//! lobe on, several roughnesses and incidences, reflection and
//! transmission, both sides; sample weights f |cos| / pdf; the sampled
//! albedo against an independent integral of f; white furnaces (energy
//! lost only as the model loses it); the diffuse albedo photon mapping
//! reads against an integral of the diffuse lobe.

mod common;

use common::chi2::{Chi2, Outcome};
use glam::Vec3;
use photonmap::material::disney::Rates;
use photonmap::material::{Material, Principled, PrincipledThin, Transport};
use photonmap::math::Color;
use photonmap::sampling::{next_2d, stream, uniform_cone, Domain};
use std::f32::consts::PI;

fn incidences() -> [Vec3; 3] {
    [
        Vec3::new(0.2, 0.1, 0.97).normalize(),
        Vec3::new(0.55, 0.35, 0.6).normalize(),
        Vec3::new(0.75, -0.6, 0.18).normalize(),
    ]
}

fn principled(f: impl FnOnce(&mut Principled)) -> Material {
    let mut p = Principled::new(Color::new(0.8, 0.45, 0.2));
    f(&mut p);
    Material::Principled(p)
}

fn thin(f: impl FnOnce(&mut PrincipledThin)) -> Material {
    let mut p = PrincipledThin::new(Color::new(0.7, 0.3, 0.5));
    f(&mut p);
    Material::PrincipledThin(p)
}

/// Parameter sets, each turning lobes on: (name, material, whether it has
/// a back worth testing).
fn materials() -> Vec<(String, Material)> {
    let mut v: Vec<(String, Material)> = vec![
        ("principled default".into(), principled(|_| {})),
        (
            "principled metallic anisotropic".into(),
            principled(|p| {
                p.metallic = 1.0;
                p.roughness = 0.35;
                p.anisotropic = 0.7;
            }),
        ),
        (
            "principled transmissive".into(),
            principled(|p| {
                p.spec_trans = 0.8;
                p.roughness = 0.4;
                p.eta = 1.5;
            }),
        ),
        (
            "principled every lobe".into(),
            principled(|p| {
                p.metallic = 0.3;
                p.spec_trans = 0.4;
                p.roughness = 0.3;
                p.anisotropic = 0.4;
                p.spec_tint = 0.5;
                p.sheen = 0.7;
                p.sheen_tint = 0.5;
                p.flatness = 0.6;
                p.clearcoat = 1.0;
                p.clearcoat_gloss = 0.5;
                p.eta = 1.33;
            }),
        ),
        (
            "principled sharp, rates".into(),
            principled(|p| {
                p.roughness = 0.25;
                p.clearcoat = 0.8;
                p.clearcoat_gloss = 0.2;
                p.spec_trans = 0.5;
                p.rates = Rates::intern([0.5, 2.0, 3.0, 1.0]).unwrap();
            }),
        ),
        (
            "thin every lobe".into(),
            thin(|p| {
                p.spec_trans = 0.6;
                p.diff_trans = 1.2;
                p.roughness = 0.3;
                p.anisotropic = 0.5;
                p.eta = 1.33;
                p.sheen = 0.5;
                p.spec_tint = 0.4;
                p.flatness = 0.3;
            }),
        ),
        ("thin diffuse".into(), thin(|p| p.diff_trans = 0.5)),
        (
            "thin specular, rates".into(),
            thin(|p| {
                p.spec_trans = 1.0;
                p.roughness = 0.5;
                p.eta = 1.8;
                p.rates = Rates::intern([2.0, 0.5, 1.0, 1.0]).unwrap();
            }),
        ),
    ];
    // The back of the transmissive ones: reflection and transmission from inside.
    let backs: Vec<(String, Material)> = v
        .iter()
        .filter(|(n, m)| n.starts_with("principled") && m.transmits())
        .map(|(n, m)| (format!("{n}, back"), m.back_side()))
        .collect();
    v.extend(backs);
    v
}

fn run_chi2(cases: Vec<(String, Material, Vec3)>, glossy: bool) {
    let n = cases.len();
    let mut failed = Vec::new();
    for (i, (name, m, wo)) in cases.into_iter().enumerate() {
        let mut rng = stream(500 + i as u64, Domain::Camera, 0);
        let chi2 = Chi2 { tests: n, ..Chi2::default() };
        let o: Outcome = if glossy {
            let g = m.glossy().expect("a glossy lobe");
            chi2.run(
                || g.sample(wo, true, Transport::Radiance, &mut rng).map(|(w, _)| w.normalize()),
                |wi| g.pdf(wo, wi, true) as f64,
            )
        } else {
            chi2.run(
                || m.sample(wo, true, Transport::Radiance, &mut rng).map(|s| s.wi.normalize()),
                |wi| m.pdf(wo, wi, true) as f64,
            )
        };
        println!(
            "{name} (glossy {glossy}) wo {wo:.2}: chi2 {:.1} dof {} p {:.4} (level {:.5}) pdf mass {:.4}",
            o.statistic, o.dof, o.p_value, o.threshold, o.pdf_mass
        );
        if !o.passed() {
            failed.push(format!("{name} wo {wo}: p {}", o.p_value));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}

#[test]
fn principled_samples_follow_their_pdf() {
    let mut cases = Vec::new();
    for (name, m) in materials() {
        for wo in incidences() {
            cases.push((name.clone(), m, wo));
        }
    }
    run_chi2(cases, false);
}

/// What photon mapping's gather rays draw: the glossy lobes alone.
#[test]
fn principled_glossy_lobes_follow_their_pdf() {
    let mut cases = Vec::new();
    for (name, m) in materials() {
        if m.glossy().is_some() {
            for wo in incidences() {
                cases.push((name.clone(), m, wo));
            }
        }
    }
    assert!(cases.len() >= 24);
    run_chi2(cases, true);
}

/// A sample's weight is eval |cos| / pdf, for the whole BSDF and for the
/// glossy lobes, both transports.
#[test]
fn sample_weights_are_f_cos_over_pdf() {
    let mut rng = stream(6, Domain::Camera, 0);
    for (name, m) in materials() {
        let mut checked = 0;
        for wo in incidences() {
            for mode in [Transport::Radiance, Transport::Importance] {
                for _ in 0..2000 {
                    if let Some(s) = m.sample(wo, true, mode, &mut rng) {
                        let want = m.eval(wo, s.wi, true, mode) * s.wi.z.abs() / m.pdf(wo, s.wi, true);
                        assert!((s.weight - want).abs().max_element() <= 1e-3 * want.max_element().max(1e-3), "{name}");
                        checked += 1;
                    }
                    if let Some(g) = m.glossy() {
                        if let Some((wi, w)) = g.sample(wo, true, mode, &mut rng) {
                            let want = g.eval(wo, wi, true, mode) * wi.z.abs() / g.pdf(wo, wi, true);
                            assert!((w - want).abs().max_element() <= 1e-3 * want.max_element().max(1e-3), "{name}");
                        }
                    }
                }
            }
        }
        assert!(checked > 5000, "{name}: {checked}");
    }
}

/// The mean weight of the samples is the integral of f |cos| over the
/// sphere, found independently with uniform directions.
#[test]
fn sampled_albedo_matches_the_integrated_one() {
    for (name, m) in materials() {
        for wo in incidences() {
            let n = 300_000;
            let mut rng = stream(7, Domain::Camera, 0);
            let mut sampled = glam::DVec3::ZERO;
            let mut integrated = glam::DVec3::ZERO;
            for _ in 0..n {
                if let Some(s) = m.sample(wo, true, Transport::Importance, &mut rng) {
                    sampled += s.weight.as_dvec3();
                }
                let wi = uniform_cone(next_2d(&mut rng), -1.0);
                integrated += (m.eval(wo, wi, true, Transport::Importance) * wi.z.abs() * 4.0 * PI).as_dvec3();
            }
            let (got, want) = ((sampled / n as f64).as_vec3(), (integrated / n as f64).as_vec3());
            let err = (got - want).abs().max_element();
            assert!(err < 0.015 + 0.03 * want.max_element(), "{name} wo {wo}: {got} vs {want}");
        }
    }
}

fn albedo(m: &Material, wo: Vec3, mode: Transport, n: usize, seed: u64) -> Color {
    let mut rng = stream(seed, Domain::Camera, 0);
    let mut sum = glam::DVec3::ZERO;
    for _ in 0..n {
        if let Some(s) = m.sample(wo, true, mode, &mut rng) {
            sum += s.weight.as_dvec3();
        }
    }
    (sum / n as f64).as_vec3()
}

/// White furnaces. A white metal (metallic 1: Schlick of white is 1), a
/// white transmissive principled (spec_trans 1: Walter's rough glass, from
/// both sides), a white thin sheet of specular lobes alone (reflection
/// with the dielectric Fresnel, transmission with the rest) lose only
/// what Smith's single scattering loses: nothing above 1, under 4% at
/// roughness 0.3 (alpha 0.09) away from grazing. The diffuse lobe of a
/// white base keeps what its shape integrates to in closed form
/// (material::disney::diffuse_albedo): the Schlick-weighted Lambert
/// without retro-reflection loses (1 - F_o / 2)(41 / 42).
#[test]
fn white_furnaces() {
    let n = 300_000;
    for roughness in [0.3f32, 0.6] {
        for wo in incidences() {
            let metal = principled(|p| {
                p.base_color = Color::ONE;
                p.metallic = 1.0;
                p.roughness = roughness;
            });
            let glass = principled(|p| {
                p.base_color = Color::ONE;
                p.spec_trans = 1.0;
                p.roughness = roughness;
            });
            let sheet = thin(|p| {
                p.base_color = Color::ONE;
                p.spec_trans = 1.0;
                p.roughness = roughness;
            });
            for (what, m) in
                [("metal", metal), ("glass", glass), ("glass from inside", glass.back_side()), ("sheet", sheet)]
            {
                let a = albedo(&m, wo, Transport::Importance, n, 11).x;
                println!("white {what} roughness {roughness} wo.z {:.2}: {a:.4}", wo.z);
                assert!(a <= 1.0 + 5e-3, "{what}: {a} over 1");
                if roughness <= 0.3 && wo.z > 0.5 {
                    assert!(a > 0.96, "{what} roughness {roughness} wo.z {}: {a}", wo.z);
                }
            }
        }
    }
    // A thin sheet without specular lobes or transmission is the diffuse
    // lobe alone: without retro-reflection (roughness 0) a white one
    // reflects (1 - F_o / 2)(41 / 42), F_o Schlick's weight at wo.
    for wo in incidences() {
        let lambert = thin(|p| {
            p.base_color = Color::ONE;
            p.roughness = 0.0;
        });
        let a = albedo(&lambert, wo, Transport::Importance, n, 12).x;
        let fo = (1.0 - wo.z).powi(5);
        let want = (1.0 - 0.5 * fo) * 41.0 / 42.0;
        assert!((a - want).abs() < 3e-3, "wo.z {}: {a} vs {want}", wo.z);
    }
}

/// What photon mapping reads at a diffuse point, the diffuse lobe's
/// albedo towards `wo` of light arriving evenly (the closed form with
/// retro-reflection, the sheen's table, the fake subsurface's
/// quadrature), against the diffuse lobe (f less the glossy lobes)
/// integrated over cosine-distributed directions.
#[test]
fn the_diffuse_albedo_photon_mapping_reads_is_the_lobe_integrated() {
    for (name, m) in materials() {
        if m.diffuse_rho().is_none() {
            continue;
        }
        for wo in incidences() {
            let mut rng = stream(13, Domain::Camera, 0);
            let n = 200_000;
            let mut sum = glam::DVec3::ZERO;
            for _ in 0..n {
                let wi = photonmap::sampling::cosine_hemisphere(next_2d(&mut rng));
                let glossy = m.glossy().map_or(Color::ZERO, |g| g.eval(wo, wi, true, Transport::Importance));
                sum += ((m.eval(wo, wi, true, Transport::Importance) - glossy) * PI).as_dvec3();
            }
            let want = (sum / n as f64).as_vec3();
            let got = m.diffuse_albedo(wo);
            assert!(
                (got - want).abs().max_element() < 0.01 + 0.02 * want.max_element(),
                "{name} wo {wo}: {got} vs {want}"
            );
        }
    }
}

/// Reflection is symmetric in its two directions (the diffuse lobe, the
/// sheen, the main reflection and the clearcoat alike).
#[test]
fn reflection_is_reciprocal() {
    let mut rng = stream(14, Domain::Camera, 0);
    for (name, m) in materials() {
        let mut checked = 0;
        for _ in 0..20_000 {
            let wo = uniform_cone(next_2d(&mut rng), 0.0);
            let wi = uniform_cone(next_2d(&mut rng), 0.0);
            let (f, back) = (m.eval(wo, wi, true, Transport::Radiance), m.eval(wi, wo, true, Transport::Radiance));
            let scale = f.max_element().max(back.max_element());
            if scale > 1e-6 {
                assert!((f - back).abs().max_element() <= 1e-3 * scale, "{name}: {wo} {wi}: {f} vs {back}");
                checked += 1;
            }
        }
        assert!(checked > 1000, "{name}");
    }
}

/// What photon mapping asks: the diffuse lobe stores photons (front only
/// for the principled), the glossy lobes carry caustics below alpha 0.3
/// (roughness 0.548), light passes where the model transmits.
#[test]
fn what_photon_mapping_asks_of_the_principled_bsdfs() {
    let smooth = principled(|p| {
        p.roughness = 0.4;
        p.spec_trans = 0.5;
    });
    assert!(smooth.diffuse_rho().is_some() && smooth.transmits());
    assert!(smooth.glossy().is_some_and(|g| g.carries_caustics() && g.transmits()) && smooth.has_specular_lobe());
    let back = smooth.back_side();
    assert!(back.diffuse_rho().is_none() && back.glossy().is_some() && back.transmits());
    let opaque_back = principled(|_| {}).back_side();
    assert!(opaque_back.glossy().is_none() && opaque_back.diffuse_rho().is_none());
    let rough = principled(|p| p.roughness = 0.6);
    assert!(rough.glossy().is_some_and(|g| !g.carries_caustics()) && !rough.transmits());
    let metal = principled(|p| p.metallic = 1.0);
    assert!(metal.diffuse_rho().is_none() && metal.glossy().is_some());
    let sheet = thin(|p| p.diff_trans = 0.5);
    assert!(sheet.diffuse_rho().is_some() && sheet.transmits() && sheet.glossy().is_some_and(|g| g.transmits()));
    assert!(thin(|_| {}).glossy().is_none() && !thin(|_| {}).transmits());
    for (name, m) in materials() {
        let p = m.photon_survival(Vec3::new(0.3, 0.2, 0.93).normalize());
        assert!(p > 0.0 && p <= 1.0, "{name}: {p}");
    }
}
