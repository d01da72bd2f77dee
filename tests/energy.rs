//! Energy: the furnace (a closed room whose every surface glows with Le and
//! reflects with albedo rho has radiance Le / (1 - rho) everywhere), for the
//! photon mapper and the path tracer; and the photon pass's books (the power
//! stored in the global map is the emitted power times 1 / (1 - rho), the
//! expected number of diffuse hits before absorption).

use photonmap::light::{AreaLight, Emitting};
use photonmap::material::Material;
use photonmap::math::Color;
use photonmap::photon::trace::{trace_pass, Pass};
use photonmap::progress::Mode;
use photonmap::render::render;
use photonmap::scene::{tncg15_room, Eye, Scene, SceneParts};
use photonmap::settings::{Method, Settings};
use photonmap::shape::Shape;

fn furnace(le: f32, rho: f32) -> Scene {
    furnace_with(le, rho, None)
}

/// The furnace with an extra sphere of `material` in the middle of the room.
fn furnace_with(le: f32, rho: f32, sphere: Option<Material>) -> Scene {
    let camera = Scene::tncg15_parts(Eye::Two).camera;
    let lights = tncg15_room(0, 0, [0; 6], 0)
        .into_iter()
        .map(|p| {
            let Shape::Triangle(t) = p.shape else { unreachable!() };
            AreaLight::unplaced(Emitting::Triangle(t), Color::splat(le), Some(0))
        })
        .collect();
    let mut materials = vec![Material::Lambertian { rho: Color::splat(rho) }];
    let mut prims = Vec::new();
    if let Some(m) = sphere {
        materials.push(m);
        let sphere = photonmap::shape::Sphere { center: glam::Vec3::new(5.0, 0.0, -2.0), radius: 2.0 };
        prims.push(photonmap::scene::Prim { shape: Shape::Sphere(sphere), material: 1, object: 0 });
    }
    Scene::from_parts(SceneParts {
        prims,
        shading_normals: Vec::new(),
        materials,
        lights,
        ambient: Color::ZERO,
        camera,
        one_sided: Vec::new(),
        paths: photonmap::scene::PathLimits::default(),
        texturing: Default::default(),
        media: Default::default(),
    })
}

/// Renders the furnace `scene` with photon mapping (2e5 photons per map,
/// 16 gather rays) and path tracing (256 spp) at 16², checks each mean
/// against `want` (4% and 2%), and returns the films.
fn furnace_renders(scene: &Scene, want: f32, label: &str) -> Vec<photonmap::film::Film> {
    let base = Settings { width: 16, height: 16, ..Settings::default() };
    let photon = Settings { photons: 200_000, caustic_photons: 200_000, spp: 4, gather_rays: 16, ..base };
    let path = Settings { method: Method::Path, spp: 256, ..base };
    let mut films = Vec::new();
    for (name, settings, tolerance) in [("photon", photon, 0.04), ("path", path, 0.02)] {
        let (film, _) = render(scene, &settings, Mode::Quiet);
        let mean = film.mean() as f32;
        eprintln!("furnace {label}, {name}: mean {mean:.4}, want {want:.4}");
        assert!((mean - want).abs() / want < tolerance, "{label} {name}: mean radiance {mean}, want {want}");
        films.push(film);
    }
    films
}

#[test]
fn furnace_radiance_is_le_over_one_minus_rho() {
    for (le, rho) in [(1.0f32, 0.5f32), (0.5, 0.8)] {
        let scene = furnace(le, rho);
        let want = le / (1.0 - rho);
        for film in furnace_renders(&scene, want, &format!("Le {le}, rho {rho}")) {
            // Uniform: the 5th to 95th percentile of pixels lie near it. (A
            // few pixels by the room's edges carry true area-sampling
            // variance: a light sample a hair away across the corner.)
            let mut v: Vec<f32> = film.pixels.iter().map(|c| c.x).collect();
            v.sort_by(f32::total_cmp);
            let (p5, p95) = (v[v.len() / 20], v[v.len() * 19 / 20]);
            assert!(
                (p5 - want).abs() / want < 0.1 && (p95 - want).abs() / want < 0.1,
                "5th/95th percentiles {p5} / {p95}, want {want}"
            );
        }
    }
}

/// A lossless mirror or a clear glass ball in the furnace changes nothing:
/// whatever it shows is radiance Le / (1 - rho) from somewhere else, so the
/// whole image stays uniform. This checks that mirrors of reflectance 1 and
/// glass lose and create no energy through every estimator (caustic map,
/// camera-path splitting, Fresnel, the (n_i / n_t)^2 radiance scaling).
#[test]
fn lossless_mirror_and_glass_keep_the_furnace_uniform() {
    let (le, rho) = (1.0f32, 0.5f32);
    let want = le / (1.0 - rho);
    for material in [Material::Mirror { reflectance: Color::ONE }, Material::glass(1.5)] {
        let scene = furnace_with(le, rho, Some(material));
        furnace_renders(&scene, want, &format!("with {material:?}"));
    }
}

#[test]
fn stored_photon_power_is_the_reflected_part_of_emitted_power_over_absorption() {
    for rho in [0.3f32, 0.8] {
        let scene = furnace(1.0, rho);
        let n = 100_000;
        let out = trace_pass(&scene, Pass::Global, n, 9, &|_| {});
        let stored: f64 = out.photons.iter().map(|p| p.power[0] as f64).sum();
        let emitted = scene.emitted_power().x as f64;
        // Every hit after the first: the first, light straight from the
        // emitter, is the cache's direct light (shadow rays), not a photon.
        let want = emitted * rho as f64 / (1.0 - rho as f64);
        eprintln!("stored power, rho {rho}: {stored:.2} vs {want:.2} ({:+.3}%)", 100.0 * (stored / want - 1.0));
        // Russian roulette makes the count of hits random: a few tenths of a
        // percent at 1e5 photons.
        assert!((stored - want).abs() / want < 0.01, "rho {rho}: stored {stored}, want {want}");
        assert!(out.photons.len() as f64 > n as f64 * rho as f64 / (1.0 - rho as f64) * 0.98);
    }
}
