//! One of every material, each held to the same three checks: its smooth
//! samples against its pdf (χ², tests/common/chi2.rs), a white furnace (a
//! white version's samples carry on at most what arrives, all of it where
//! the model loses nothing), and reciprocity of its reflection. The list
//! is made by a `match` over every variant, so that a new material fails
//! to compile here until it is given a case. The families' own files test
//! each in depth (roughnesses, distributions, both transports):
//! bsdf_chi2.rs, bsdf_energy.rs, bsdf_principled.rs, bsdf_blend.rs.

mod common;

use glam::Vec3;
use photonmap::material::{Blend, Distribution, Masked, Material, Phong, Principled, PrincipledThin, Transport};
use photonmap::math::Color;
use photonmap::sampling::{next_2d, stream, uniform_cone, Domain};

/// What a white version of a material keeps in a furnace.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Keeps {
    /// All that arrives (to 1%).
    All,
    /// At most all, and more than 0.3 (microfacet models lose Smith's
    /// single-scattering share; the course's Phong lobe is not normalised).
    AtMost,
    /// Nothing: it is not a surface that scatters (a light's own surface;
    /// a blend, which the scene resolves to one of its two materials
    /// before any of this is asked; bsdf_blend.rs tests the resolved mix).
    Nothing,
}

/// The case of each variant: (name, a coloured one, a white one, what the
/// white one keeps). Exhaustive on purpose: no `_` arm.
fn case(variant: &Material) -> (&'static str, Material, Material, Keeps) {
    let c = Color::new(0.8, 0.5, 0.2);
    let phong = |color: Color| Phong {
        color,
        ambient: 0.0,
        diffuse: 0.4,
        specular: 0.3,
        metalness: 0.2,
        shininess: 20.0,
        mirror: 0.2,
    };
    let principled = |base: Color| {
        let mut p = Principled::new(base);
        p.roughness = 0.4;
        p.spec_trans = 0.3;
        p
    };
    let thin = |base: Color| {
        let mut p = PrincipledThin::new(base);
        p.roughness = 0.4;
        p.spec_trans = 0.3;
        p
    };
    match variant {
        Material::Lambertian { .. } => {
            ("lambertian", Material::Lambertian { rho: c }, Material::Lambertian { rho: Color::ONE }, Keeps::All)
        }
        Material::Mirror { .. } => {
            ("mirror", Material::Mirror { reflectance: c }, Material::Mirror { reflectance: Color::ONE }, Keeps::All)
        }
        Material::Glass { .. } => ("glass", Material::glass(1.5), Material::glass(1.5), Keeps::All),
        Material::Phong(_) => ("phong", Material::Phong(phong(c)), Material::Phong(phong(Color::ONE)), Keeps::AtMost),
        Material::Conductor(_) => (
            "conductor",
            Material::conductor(Color::new(0.2, 0.9, 1.1), Color::new(3.9, 2.4, 2.2), Color::ONE),
            Material::conductor(Color::ZERO, Color::ONE, Color::ONE),
            Keeps::All,
        ),
        Material::RoughConductor(_) => (
            "roughconductor",
            Material::rough_conductor(
                Distribution::Ggx,
                0.3,
                0.3,
                Color::new(0.2, 0.9, 1.1),
                Color::new(3.9, 2.4, 2.2),
                Color::ONE,
            ),
            Material::rough_conductor(Distribution::Ggx, 0.3, 0.3, Color::ZERO, Color::ONE, Color::ONE),
            Keeps::AtMost,
        ),
        Material::RoughDielectric(_) => (
            "roughdielectric",
            Material::rough_dielectric(Distribution::Beckmann, 0.3, 0.3, 1.5, 1.0, Color::ONE, Color::ONE),
            Material::rough_dielectric(Distribution::Beckmann, 0.3, 0.3, 1.5, 1.0, Color::ONE, Color::ONE),
            Keeps::AtMost,
        ),
        Material::ThinDielectric(_) => (
            "thindielectric",
            Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE),
            Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE),
            Keeps::All,
        ),
        Material::Plastic(_) => (
            "plastic",
            Material::plastic(c, Color::ONE, 1.49, 1.0, false),
            Material::plastic(Color::ONE, Color::ONE, 1.49, 1.0, false),
            Keeps::All,
        ),
        Material::RoughPlastic(_) => (
            "roughplastic",
            Material::rough_plastic(Distribution::Ggx, 0.2, c, Color::ONE, 1.49, 1.0, false),
            Material::rough_plastic(Distribution::Ggx, 0.2, Color::ONE, Color::ONE, 1.49, 1.0, false),
            Keeps::AtMost,
        ),
        Material::Masked(_) => (
            "mask",
            Material::Masked(Masked { opacity: 0.6, rho: c }),
            Material::Masked(Masked { opacity: 0.6, rho: Color::ONE }),
            Keeps::All,
        ),
        // Burley's diffuse lobe is not energy conserving (its
        // retro-reflection returns more than a Lambertian: 1.027 from the
        // normal for a white base), so the white ones are the specular
        // lobes alone: a white metal, a white sheet of spec_trans 1.
        Material::Principled(_) => (
            "principled",
            Material::Principled(principled(c)),
            Material::Principled(Principled { metallic: 1.0, ..principled(Color::ONE) }),
            Keeps::AtMost,
        ),
        Material::PrincipledThin(_) => (
            "principledthin",
            Material::PrincipledThin(thin(c)),
            Material::PrincipledThin(PrincipledThin { spec_trans: 1.0, ..thin(Color::ONE) }),
            Keeps::AtMost,
        ),
        Material::Blend(_) => {
            let b = Material::Blend(Blend::of(0.5, &Material::Lambertian { rho: c }, &Material::glass(1.5)));
            ("blend", b, b, Keeps::Nothing)
        }
        Material::Emitter => ("emitter", Material::Emitter, Material::Emitter, Keeps::Nothing),
    }
}

/// One of every variant.
fn every() -> Vec<(&'static str, Material, Material, Keeps)> {
    let lambertian = Material::Lambertian { rho: Color::ONE };
    [
        lambertian,
        Material::Mirror { reflectance: Color::ONE },
        Material::glass(1.5),
        Material::Phong(Phong {
            color: Color::ONE,
            ambient: 0.0,
            diffuse: 1.0,
            specular: 0.0,
            metalness: 0.0,
            shininess: 1.0,
            mirror: 0.0,
        }),
        Material::conductor(Color::ZERO, Color::ONE, Color::ONE),
        Material::rough_conductor(Distribution::Ggx, 0.3, 0.3, Color::ZERO, Color::ONE, Color::ONE),
        Material::rough_dielectric(Distribution::Ggx, 0.3, 0.3, 1.5, 1.0, Color::ONE, Color::ONE),
        Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE),
        Material::plastic(Color::ONE, Color::ONE, 1.49, 1.0, false),
        Material::rough_plastic(Distribution::Ggx, 0.2, Color::ONE, Color::ONE, 1.49, 1.0, false),
        Material::Masked(Masked { opacity: 1.0, rho: Color::ONE }),
        Material::Principled(Principled::new(Color::ONE)),
        Material::PrincipledThin(PrincipledThin::new(Color::ONE)),
        Material::Blend(Blend::of(0.5, &lambertian, &lambertian)),
        Material::Emitter,
    ]
    .iter()
    .map(case)
    .collect()
}

/// Incident directions: near normal, oblique, grazing.
fn incidences() -> [Vec3; 3] {
    [
        Vec3::new(0.2, 0.1, 0.97).normalize(),
        Vec3::new(0.55, 0.35, 0.6).normalize(),
        Vec3::new(0.75, -0.6, 0.18).normalize(),
    ]
}

/// The sides a material is met from: both for those light passes through.
fn sides(m: &Material) -> &'static [bool] {
    match m {
        Material::Glass { .. }
        | Material::RoughDielectric(_)
        | Material::ThinDielectric(_)
        | Material::PrincipledThin(_)
        | Material::Masked(_) => &[true, false],
        _ => &[true],
    }
}

/// Every variant has a case, and its smooth samples follow its pdf from
/// every incidence and side (the specular branches, deltas, left out: the
/// pdf's mass is the rest).
#[test]
fn every_material_samples_follow_its_pdf() {
    let cases: Vec<(String, Material, Vec3, bool)> = every()
        .into_iter()
        .flat_map(|(name, m, _, _)| {
            incidences().into_iter().flat_map(move |wo| sides(&m).iter().map(move |&e| (name.to_string(), m, wo, e)))
        })
        .collect();
    common::material_chi2::check_all("every", cases, 200_000, 300);
}

/// The mean weight of `n` samples from `wo`: what the material carries on.
fn albedo(m: &Material, wo: Vec3, entering: bool, n: usize, seed: u64) -> f64 {
    let mut rng = stream(seed, Domain::Camera, 0);
    let mut sum = 0.0;
    for _ in 0..n {
        if let Some(s) = m.sample(wo, entering, Transport::Importance, &mut rng) {
            sum += s.weight.x as f64;
        }
    }
    sum / n as f64
}

/// White furnaces: a white material keeps all that arrives where its
/// model loses nothing, at most all where it does, nothing where it is
/// not a scattering surface.
#[test]
fn every_white_material_keeps_what_its_model_keeps() {
    for (name, _, white, keeps) in every() {
        for wo in incidences() {
            for &entering in sides(&white) {
                let a = albedo(&white, wo, entering, 200_000, 7);
                println!("white {name} wo.z {:.2} entering {entering}: {a:.4}", wo.z);
                match keeps {
                    Keeps::All => assert!((a - 1.0).abs() < 0.01, "{name} wo {wo} entering {entering}: {a}"),
                    Keeps::AtMost => assert!(a <= 1.01 && a > 0.3, "{name} wo {wo} entering {entering}: {a}"),
                    Keeps::Nothing => assert_eq!(a, 0.0, "{name}"),
                }
            }
        }
    }
}

/// Reciprocity of reflection: f(wo, wi) = f(wi, wo) for directions on the
/// same side, to 1% (microfacet lobes' sharp D magnifies rounding).
#[test]
fn every_reflection_is_reciprocal() {
    let mut rng = stream(9, Domain::Camera, 0);
    for (name, m, _, _) in every() {
        let mut checked = 0;
        for _ in 0..20_000 {
            let wo = uniform_cone(next_2d(&mut rng), 0.0);
            let wi = uniform_cone(next_2d(&mut rng), 0.0);
            for &entering in sides(&m) {
                let f = m.eval(wo, wi, entering, Transport::Radiance);
                let back = m.eval(wi, wo, entering, Transport::Radiance);
                let scale = f.max_element().max(back.max_element());
                if scale < 1e-6 {
                    continue;
                }
                assert!((f - back).abs().max_element() <= 1e-2 * scale, "{name}: {wo} {wi} {entering}: {f} vs {back}");
                checked += 1;
            }
        }
        println!("{name}: {checked} pairs");
        // Those with a smooth reflecting lobe were checked at all.
        let smooth = m.pdf(Vec3::Z, Vec3::new(0.3, 0.2, 0.93).normalize(), true) > 0.0;
        assert!(!smooth || checked > 10_000, "{name}: {checked}");
    }
}
