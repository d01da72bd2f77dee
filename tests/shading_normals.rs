//! Smooth meshes: a glass sphere made of 20,480 triangles with vertex
//! normals renders as the analytic sphere does, within noise; the same
//! mesh shaded flat (faceted) does not, so the test can fail.

use photonmap::film::Film;
use photonmap::metrics::{compare_images, Window};
use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::scene::procedural::icosphere;
use photonmap::scene::{Eye, Prim, Scene};
use photonmap::settings::Settings;
use photonmap::shape::{Shape, Triangle};

/// The default room with its glass sphere, or that sphere as a mesh
/// (smooth: with its vertex normals; else faceted).
fn room(mesh: Option<(u32, bool)>) -> Scene {
    let mut parts = Scene::tncg15_parts(Eye::One);
    if let Some((subdivisions, smooth)) = mesh {
        let glass = parts.prims.iter().position(|p| matches!(p.shape, Shape::Sphere(s) if s.radius == 1.5)).unwrap();
        let Prim { shape: Shape::Sphere(s), material, object } = parts.prims.remove(glass) else { unreachable!() };
        let m = icosphere(subdivisions).mapped(|p| s.center + p * s.radius, |n| n);
        for f in &m.faces {
            let [a, b, c] = f.map(|i| m.positions[i as usize]);
            let mut t = Triangle::new(a, b, c);
            if smooth {
                t.shading = parts.shading_normals.len() as u32;
                parts.shading_normals.push(f.map(|i| m.normals[i as usize]));
            }
            parts.prims.push(Prim { shape: Shape::Triangle(t), material, object });
        }
    }
    Scene::from_parts(parts)
}

fn render_room(scene: &Scene, seed: u64) -> Film {
    let settings = Settings {
        photons: 100_000,
        caustic_photons: 600_000,
        spp: 4,
        width: 200,
        height: 200,
        seed,
        ..Settings::default()
    };
    let (film, stats) = render(scene, &settings, Mode::Quiet);
    assert_eq!(stats.camera.nonfinite, 0);
    film
}

/// The 20,480-triangle smooth mesh against the analytic sphere, in the
/// caustic window and in the window through the sphere, as far off as a
/// render of another seed; a 1,280-triangle mesh shaded flat is clearly
/// farther off through the sphere, and shaded smooth it is not.
#[test]
fn a_smooth_glass_mesh_renders_as_the_analytic_sphere() {
    let analytic = room(None);
    let (a1, a2) = (render_room(&analytic, 1), render_room(&analytic, 2));
    let fine = render_room(&room(Some((5, true))), 3);
    let coarse_flat = render_room(&room(Some((3, false))), 3);
    let coarse_smooth = render_room(&room(Some((3, true))), 3);
    let caustic = Window::default_caustic(200);
    // Below the sphere and through it: its caustic, and the room seen
    // through the glass.
    let through = Window { name: "through the sphere".into(), rows: (100, 193), cols: (110, 175) };
    let windows = [caustic, through];
    let score = |f: &Film| compare_images(f, &a1, &windows).unwrap();
    let (seeds, fine, flat, smooth) = (score(&a2), score(&fine), score(&coarse_flat), score(&coarse_smooth));
    for (k, w) in windows.iter().enumerate() {
        let rmse = |c: &photonmap::metrics::Comparison| c.windows[k].1.rmse;
        let noise = rmse(&seeds);
        eprintln!(
            "{}: seed to seed {noise:.5}; 20k smooth {:.5}; 1280 flat {:.5}, smooth {:.5}",
            w.name,
            rmse(&fine),
            rmse(&flat),
            rmse(&smooth)
        );
        assert!(rmse(&fine) < 1.25 * noise, "{}: the smooth mesh is {} off, another seed {noise}", w.name, rmse(&fine));
    }
    let noise = seeds.windows[1].1.rmse;
    assert!(flat.windows[1].1.rmse > 1.3 * noise, "a faceted sphere should show through the glass");
    assert!(smooth.windows[1].1.rmse < 1.15 * noise, "its vertex normals should hide the facets");
    let bias = fine.windows[0].1.bias() - seeds.windows[0].1.bias();
    assert!(bias.abs() < 0.03, "caustic mean off by {bias}");
}
