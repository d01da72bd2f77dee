//! A glossy floor under the glass sphere: every light path into a Phong
//! surface is counted by exactly one of photon mapping's estimators
//! (notes/method.md), so photon mapping agrees with the path tracer: the
//! image mean within 1%, the glossy caustic's window within 5%.

use photonmap::film::Film;
use photonmap::material::{Material, Phong};
use photonmap::math::Color;
use photonmap::metrics::{compare_images, Window};
use photonmap::progress::Mode;
use photonmap::render::{render, render_progressive, Budget};
use photonmap::scene::{Eye, Scene};
use photonmap::settings::{Method, Settings};
use photonmap::shape::Shape;

/// The default room, its floor glossy grey: diffuse 0.08, a Phong lobe of
/// 0.8 and exponent 200, in which the glass sphere's focused light shows.
fn glossy_room() -> Scene {
    let mut parts = Scene::tncg15_parts(Eye::One);
    parts.materials.push(Material::Phong(Phong {
        color: Color::splat(0.8),
        ambient: 0.0,
        diffuse: 0.1,
        specular: 0.8,
        metalness: 0.0,
        shininess: 200.0,
        mirror: 0.0,
    }));
    let glossy = parts.materials.len() as u32 - 1;
    for p in parts.prims.iter_mut() {
        if let Shape::Triangle(t) = p.shape {
            if t.normal.z > 0.99 && t.v0.z == -5.0 {
                p.material = glossy;
            }
        }
    }
    Scene::from_parts(parts)
}

/// The path tracer's image: 24 independent passes of 16 spp, averaged.
/// (Without the glossy lobe's caustics, photon mapping's window read
/// -10.7% against 12 such passes; with them -4.2%, and -3.2% against 48.)
fn path_traced(scene: &Scene, size: u32) -> Film {
    let s = Settings { method: Method::Path, spp: 16, width: size, height: size, seed: 11, ..Settings::default() };
    render_progressive(scene, &s, Budget::passes(24), |_| {}).0
}

#[test]
fn a_glossy_floor_agrees_with_the_path_tracer() {
    let scene = glossy_room();
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
    // The glass sphere's focused light seen in the floor's glossy lobe.
    let caustic = Window { name: "glossy caustic".into(), rows: (70, 90), cols: (60, 90) };
    let c = compare_images(&film, &reference, std::slice::from_ref(&caustic)).unwrap();
    eprintln!(
        "mean {:+.2}%, caustic window {:+.2}% (rmse {:.4})",
        100.0 * c.whole.bias(),
        100.0 * c.windows[0].1.bias(),
        c.windows[0].1.rmse
    );
    assert!(c.whole.bias().abs() < 0.01, "mean {:+.2}%", 100.0 * c.whole.bias());
    assert!(c.windows[0].1.bias().abs() < 0.05, "glossy caustic {:+.2}%", 100.0 * c.windows[0].1.bias());
}
