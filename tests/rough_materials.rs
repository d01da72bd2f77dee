//! The default room with rough materials: its glass sphere frosted (GGX
//! alpha 0.1, a lobe that carries caustics), its mirror rough gold (alpha
//! 0.4, a lobe final gathering takes), its floor a rough plastic (alpha
//! 0.2). Every light path is counted by exactly one of photon mapping's
//! estimators (notes/method.md), so photon mapping agrees with the path
//! tracer: the image mean within 1.5%, the frosted sphere's caustic on the
//! floor within 5%. And the scene file reads the new materials, refusing
//! bad ones at their place.

use photonmap::film::Film;
use photonmap::material::{Distribution, Material};
use photonmap::math::Color;
use photonmap::metrics::{compare_images, Window};
use photonmap::progress::Mode;
use photonmap::render::{render, render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings};
use photonmap::shape::Shape;
use std::path::Path;

fn rough_room() -> Scene {
    let mut parts = Scene::tncg15_parts(Eye::One);
    for m in parts.materials.iter_mut() {
        *m = match *m {
            Material::Glass { .. } => {
                Material::rough_dielectric(Distribution::Ggx, 0.1, 0.1, 1.5, 1.0, Color::ONE, Color::ONE)
            }
            Material::Mirror { .. } => Material::rough_conductor(
                Distribution::Beckmann,
                0.4,
                0.4,
                Color::new(0.143, 0.374, 1.442),
                Color::new(3.983, 2.385, 1.603),
                Color::ONE,
            ),
            other => other,
        };
    }
    parts.materials.push(Material::rough_plastic(
        Distribution::Ggx,
        0.2,
        Color::splat(0.6),
        Color::ONE,
        1.49,
        1.0,
        false,
    ));
    let floor = parts.materials.len() as u32 - 1;
    for p in parts.prims.iter_mut() {
        if let Shape::Triangle(t) = p.shape {
            if t.normal.z > 0.99 && t.v0.z == -5.0 {
                p.material = floor;
            }
        }
    }
    Scene::from_parts(parts)
}

fn path_traced(scene: &Scene, size: u32) -> Film {
    let s = Settings { method: Method::Path, spp: 16, width: size, height: size, seed: 11, ..Settings::default() };
    render_progressive(scene, &s, Budget::passes(16), |_| {}).0
}

#[test]
fn a_rough_room_agrees_with_the_path_tracer() {
    let scene = rough_room();
    let size = 100;
    let reference = path_traced(&scene, size);
    let photon = Settings {
        photons: 300_000,
        caustic_photons: 600_000,
        spp: 16,
        width: size,
        height: size,
        ..Settings::default()
    };
    let (film, stats) = render(&scene, &photon, Mode::Quiet);
    assert_eq!(stats.camera.nonfinite, 0);
    // The frosted sphere's caustic on the floor.
    let caustic = Window { name: "frosted caustic".into(), rows: (70, 90), cols: (60, 90) };
    let c = compare_images(&film, &reference, std::slice::from_ref(&caustic)).unwrap();
    eprintln!(
        "mean {:+.2}%, caustic window {:+.2}% (rmse {:.4}), whole rmse {:.4}",
        100.0 * c.whole.bias(),
        100.0 * c.windows[0].1.bias(),
        c.windows[0].1.rmse,
        c.whole.rmse
    );
    assert!(c.whole.bias().abs() < 0.015, "mean {:+.2}%", 100.0 * c.whole.bias());
    assert!(c.windows[0].1.bias().abs() < 0.05, "frosted caustic {:+.2}%", 100.0 * c.windows[0].1.bias());
}

const GOOD: &str = r#"
[camera]
eye = [-2, 0, 0]
lower_left = [0, 1, -1]
lower_right = [0, -1, -1]
upper_left = [0, 1, 1]
upper_right = [0, -1, 1]
width = 16
height = 16

[materials.gold]
type = "roughconductor"
distribution = "ggx"
alpha_u = 0.1
alpha_v = 0.3
eta = [0.143, 0.374, 1.442]
k = [3.983, 2.385, 1.603]

[materials.chrome]
type = "conductor"

[materials.frosted]
type = "roughdielectric"
alpha = 0.1
int_ior = 1.5
ext_ior = 1.0

[materials.pane]
type = "thindielectric"

[materials.red]
type = "plastic"
diffuse_reflectance = [0.8, 0.1, 0.1]
nonlinear = true

[materials.varnish]
type = "roughplastic"
distribution = "beckmann"
alpha = 0.2
diffuse_reflectance = [0.5, 0.3, 0.1]

[[shapes]]
type = "sphere"
center = [5, 0, 0]
radius = 1
material = "gold"
"#;

/// Each new type reads with Mitsuba's defaults where a field is left out.
#[test]
fn the_scene_file_reads_the_new_materials() {
    let file = photonmap::scene::file::parse(GOOD, Path::new("rough.toml")).unwrap_or_else(|e| panic!("{e}"));
    let m = &file.parts.materials;
    let find = |f: &dyn Fn(&Material) -> bool| m.iter().find(|x| f(x)).copied().expect("the material");
    let Material::RoughConductor(gold) = find(&|x| matches!(x, Material::RoughConductor(_))) else { panic!() };
    assert_eq!(
        (gold.microfacet.distribution, gold.microfacet.alpha_u, gold.microfacet.alpha_v),
        (Distribution::Ggx, 0.1, 0.3)
    );
    assert_eq!(gold.specular, Color::ONE);
    let Material::Conductor(chrome) = find(&|x| matches!(x, Material::Conductor(_))) else { panic!() };
    assert_eq!((chrome.eta, chrome.k), (Color::ZERO, Color::ONE));
    let Material::RoughDielectric(d) = find(&|x| matches!(x, Material::RoughDielectric(_))) else { panic!() };
    assert_eq!((d.microfacet.distribution, d.microfacet.alpha_u, d.int_ior), (Distribution::Beckmann, 0.1, 1.5));
    let Material::ThinDielectric(t) = find(&|x| matches!(x, Material::ThinDielectric(_))) else { panic!() };
    assert_eq!((t.int_ior, t.ext_ior), (1.5046, 1.000277));
    let Material::Plastic(p) = find(&|x| matches!(x, Material::Plastic(_))) else { panic!() };
    assert!(p.nonlinear && (p.eta - 1.49 / 1.000277).abs() < 1e-6);
    let Material::RoughPlastic(r) = find(&|x| matches!(x, Material::RoughPlastic(_))) else { panic!() };
    assert!(!r.nonlinear && r.microfacet.alpha_u == 0.2 && r.specular == Color::ONE);
}

/// Bad fields are refused with the file, line, column and field.
#[test]
fn bad_rough_materials_are_refused_at_their_place() {
    let cases = [
        ("distribution = \"ggx\"", "distribution = \"phong\"", "unknown distribution \"phong\""),
        ("alpha_u = 0.1\nalpha_v = 0.3", "alpha = 0.2\nalpha_u = 0.1", "either `alpha` or `alpha_u`"),
        ("alpha_u = 0.1\nalpha_v = 0.3", "alpha_u = 0.1", "go together"),
        ("alpha = 0.1\nint_ior = 1.5", "alpha = 0.1\nint_ior = 1.0", "must differ"),
        ("alpha = 0.2\ndiffuse_reflectance", "alpha_u = 0.2\nalpha_v = 0.1\ndiffuse_reflectance", "isotropic"),
        ("nonlinear = true", "nonlinear = true\nalpha = 0.1", "does not apply"),
        ("diffuse_reflectance = [0.8, 0.1, 0.1]", "diffuse_reflectance = [1.8, 0.1, 0.1]", "must lie in [0, 1]"),
        ("alpha = 0.1\nint_ior", "alpha = -0.1\nint_ior", "must lie in [0, 10]"),
    ];
    for (from, to, want) in cases {
        assert!(GOOD.contains(from), "{from}");
        let text = GOOD.replacen(from, to, 1);
        let Err(err) = photonmap::scene::file::parse(&text, Path::new("rough.toml")) else { panic!("accepted: {to}") };
        let err = err.to_string();
        assert!(err.contains("rough.toml:") && err.contains("materials.") && err.contains(want), "{to}: {err}");
    }
}
