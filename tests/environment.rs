//! Light from everywhere: the scene file's `sky` and `envmap` lights
//! (a map written here as Radiance HDR), their refusals, their export to
//! Mitsuba and back, and the map's sampling against its pdf by the χ²
//! harness.

mod common;

use common::chi2::Chi2;
use common::{render_quiet, scratch_dir};
use glam::{Mat3, Vec2, Vec3};
use photonmap::envmap::EnvMap;
use photonmap::film::Film;
use photonmap::light::Light;
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};

/// A sky of `base` with a sun: a bright disc of `sun` around (u, v) =
/// (0.3, 0.3), 3 pixels across, on a `w` x `h` map, and a blue gradient.
fn sunny(w: u32, h: u32, base: f32, sun: f32) -> Film {
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let d = Vec2::new((u - 0.3) * w as f32, (v - 0.3) * h as f32).length();
            let sky = Vec3::new(base, base * 1.2, base * (1.5 + v));
            pixels.push(if d < 1.5 { Vec3::splat(sun) } else { sky });
        }
    }
    Film { width: w, height: h, pixels }
}

/// A scene file: a diffuse sphere (reflectance 0.5) at the origin seen
/// from 3 away, 16² pixels, lit by `light`.
fn scene(light: &str) -> String {
    format!(
        r#"[camera]
eye = [0, -3, 0]
target = [0, 0, 0]
up = [0, 0, 1]
vfov = 60
width = 16
height = 16

[materials.grey]
type = "lambertian"
rho = [0.5, 0.5, 0.5]

[[shapes]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "grey"

[[lights]]
{light}
"#
    )
}

fn settings(method: Method, spp: u32) -> Settings {
    Settings { method, photons: 20_000, caustic_photons: 0, spp, width: 16, height: 16, ..Settings::default() }
}

/// The mean of the 6 x 6 pixels in the image's middle, on the sphere.
fn centre(film: &Film) -> Vec3 {
    (5..11).flat_map(|r| (5..11).map(move |c| (c, r))).map(|(c, r)| film.get(c, r)).sum::<Vec3>() / 36.0
}

/// A furnace in a scene file: the diffuse sphere under a sky of radiance
/// 2, or a map of constant value 2 written as HDR and turned, reflects
/// ρ L = 1 everywhere (convex: each point sees the whole sky above it);
/// the sky is seen behind it.
#[test]
fn sky_and_envmap_in_a_scene_file_make_a_furnace() {
    let dir = scratch_dir("toml_environment");
    let flat = Film { width: 32, height: 16, pixels: vec![Vec3::splat(2.0); 512] };
    std::fs::write(dir.join("flat.hdr"), photonmap::output::hdr_bytes(&flat).unwrap()).unwrap();
    let lights = [
        "type = \"sky\"\nradiance = [2, 2, 2]",
        "type = \"envmap\"\nfile = \"flat.hdr\"\ntransform = [{ rotate = { axis = [1, 0, 0], degrees = 90 } }]",
        "type = \"envmap\"\nfile = \"flat.hdr\"\nscale = 4",
    ];
    for (k, light) in lights.iter().enumerate() {
        let path = dir.join(format!("s{k}.toml"));
        std::fs::write(&path, scene(light)).unwrap();
        let file = photonmap::scene::file::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let scene = Scene::from_parts(file.parts);
        let l = if k == 2 { 4.0 } else { 1.0 };
        for method in [Method::Photon, Method::Path] {
            let film = render_quiet(&scene, &settings(method, 64));
            let c = centre(&film);
            assert!((c - Vec3::splat(l)).abs().max_element() < 0.03 * l, "{light} {method:?}: {c}");
            assert!((film.get(0, 0) - Vec3::splat(2.0 * l)).abs().max_element() < 1e-4 * l, "{}", film.get(0, 0));
        }
    }
}

/// What the scene file refuses of light from everywhere, at its place.
#[test]
fn environment_refusals_are_located() {
    let dir = scratch_dir("toml_environment_refusals");
    std::fs::write(dir.join("flat.hdr"), photonmap::output::hdr_bytes(&sunny(8, 4, 1.0, 5.0)).unwrap()).unwrap();
    std::fs::write(dir.join("broken.hdr"), b"#?RADIANCE\nnonsense").unwrap();
    let cases = [
        ("type = \"envmap\"\nfile = \"none.hdr\"", "s.toml:21:8", "lights[0].file", "none.hdr"),
        ("type = \"envmap\"\nfile = \"broken.hdr\"", "s.toml:21:8", "lights[0].file", "cannot decode"),
        (
            "type = \"envmap\"\nfile = \"flat.hdr\"\ntransform = [{ translate = [0, 0, 1] }]",
            "s.toml:22:14",
            "lights[0].transform[0]",
            "only turned",
        ),
        ("type = \"envmap\"\nfile = \"flat.hdr\"\nscale = -1", "s.toml:22:9", "lights[0].scale", "got -1"),
        ("type = \"sky\"\nradiance = [1, -1, 1]", "s.toml:21:12", "lights[0].radiance", ""),
        ("type = \"sky\"\nradiance = [1, 1, 1]\nfile = \"x\"", "s.toml:", "lights[0]", "unknown field `file`"),
    ];
    for (light, place, field, message) in cases {
        let path = dir.join("s.toml");
        std::fs::write(&path, scene(light)).unwrap();
        let e = photonmap::scene::file::load(&path).err().unwrap_or_else(|| panic!("{light}: loaded")).to_string();
        assert!(e.contains(place) && e.contains(field) && e.contains(message), "{light}: {e}");
    }
}

/// A scene of a sky and a sunny map, turned, exported for Mitsuba and
/// read back by the XML front-end: the same map to the bit (written as a
/// float EXR beside the scene), the same turn, the same sky; the two
/// scenes render the same image.
#[test]
fn environments_survive_the_export_and_the_import() {
    use photonmap::export::mitsuba::{to_mitsuba, Placement};
    let dir = scratch_dir("environment_export");
    std::fs::write(dir.join("sun.hdr"), photonmap::output::hdr_bytes(&sunny(32, 16, 0.5, 40.0)).unwrap()).unwrap();
    let light = "type = \"envmap\"\nfile = \"sun.hdr\"\nscale = 1.5\ntransform = [{ rotate = { axis = [1, 0, 0], degrees = 90 } }, { rotate = { axis = [0, 0, 1], degrees = 30 } }]\n\n[[lights]]\ntype = \"sky\"\nradiance = [0.1, 0.2, 0.3]";
    let path = dir.join("s.toml");
    std::fs::write(&path, scene(light)).unwrap();
    let file = photonmap::scene::file::load(&path).unwrap();
    let out = to_mitsuba(&file.parts, Some(&file.origins), "m", Placement::new(Vec3::ZERO, 1.0).unwrap())
        .unwrap_or_else(|r| panic!("{}", r.describe(Some(&file.origins))));
    assert!(out.xml.contains("type=\"envmap\"") && out.xml.contains("type=\"constant\""), "{}", out.xml);
    std::fs::create_dir_all(dir.join("m")).unwrap();
    for (name, bytes) in &out.meshes {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    std::fs::write(dir.join("s.xml"), &out.xml).unwrap();
    let back = photonmap::scene::mitsuba::load(&dir.join("s.xml"), &Default::default()).unwrap().file.parts;
    let maps = |lights: &[Light]| {
        lights
            .iter()
            .filter_map(|l| if let Light::Envmap(e) = l { Some(e.map.image()) } else { None })
            .collect::<Vec<_>>()
    };
    let (a, b) = (maps(&file.parts.lights), maps(&back.lights));
    assert_eq!((a.len(), b.len()), (1, 1));
    assert_eq!(a[0].0.pixels, b[0].0.pixels, "the texels, bit for bit");
    assert!((a[0].1 - b[0].1).abs().to_cols_array().iter().all(|d| *d < 1e-6), "{} vs {}", a[0].1, b[0].1);
    let render = |parts| render_quiet(&Scene::from_parts(parts), &settings(Method::Photon, 16));
    let (fa, fb) = (render(file.parts), render(back));
    let worst = fa.pixels.iter().zip(&fb.pixels).map(|(p, q)| (*p - *q).abs().max_element()).fold(0.0, f32::max);
    assert!(worst < 1e-3 * fa.mean() as f32, "{worst} of {}", fa.mean());
}

/// The map's sampling against its pdf, by the χ² harness, on a sunny map
/// turned in the world (the harness bins directions about world z): the
/// sun's few pixels draw most samples, the gradient the rest; the pdf
/// a sample comes with is the pdf of its direction.
#[test]
fn the_maps_sampling_follows_its_pdf() {
    let turn = Mat3::from_axis_angle(Vec3::new(1.0, 0.5, 0.2).normalize(), 0.7);
    let map = EnvMap::new(&sunny(64, 32, 0.5, 400.0), 1.0, turn);
    let mut rng = photonmap::sampling::stream(3, photonmap::sampling::Domain::Camera, 0);
    let mut mismatched = 0;
    let outcome = Chi2 { cos_bins: 32, phi_bins: 64, samples: 1_000_000, ..Chi2::default() }.run(
        || {
            let (d, pdf) = map.sample(photonmap::sampling::next_2d(&mut rng));
            mismatched += ((pdf - map.pdf(d)).abs() > 1e-3 * pdf) as u32;
            (pdf > 0.0).then_some(d)
        },
        |w| map.pdf(w) as f64,
    );
    assert!(outcome.passed(), "{outcome:?}");
    assert!((outcome.pdf_mass - 1.0).abs() < 2e-3, "{outcome:?}");
    assert!(mismatched < 1000, "{mismatched} samples' pdfs differ from their direction's");
}

/// The sun carries most of the map's light and most of its samples.
#[test]
fn a_sun_draws_its_share() {
    let map = EnvMap::new(&sunny(64, 32, 0.5, 400.0), 1.0, Mat3::IDENTITY);
    let mut rng = photonmap::sampling::stream(4, photonmap::sampling::Domain::Camera, 0);
    let n = 100_000;
    let bright = (0..n).filter(|_| map.eval(map.sample(photonmap::sampling::next_2d(&mut rng)).0).x > 100.0).count();
    assert!(bright as f64 > 0.5 * n as f64, "{bright} of {n}");
}

/// A glass ball on a floor under a map with a sun: the caustic photons
/// start from the pass's Sobol points, keyed by the photon's index as its
/// random stream is, so the image is the same bits on 1, 2 and 3 threads
/// (and a progressive render's, whose passes go on along one sequence),
/// and another seed makes another image.
#[test]
fn an_envmaps_caustic_is_the_same_on_any_number_of_threads() {
    let dir = scratch_dir("envmap_threads");
    std::fs::write(dir.join("sun.hdr"), photonmap::output::hdr_bytes(&sunny(32, 16, 0.5, 400.0)).unwrap()).unwrap();
    let text = r#"[camera]
eye = [0, -3, 2]
target = [0, 0, 0.3]
up = [0, 0, 1]
vfov = 50
width = 16
height = 16

[materials.floor]
type = "lambertian"
rho = [0.7, 0.7, 0.7]

[materials.glass]
type = "glass"
ior = 1.5

[[shapes]]
type = "quad"
vertices = [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]]
material = "floor"

[[shapes]]
type = "sphere"
center = [0, 0, 0.51]
radius = 0.5
material = "glass"

[[lights]]
type = "envmap"
file = "sun.hdr"
transform = [{ rotate = { axis = [1, 0, 0], degrees = 90 } }]
"#;
    let path = dir.join("ball.toml");
    std::fs::write(&path, text).unwrap();
    let scene = Scene::from_parts(photonmap::scene::file::load(&path).unwrap_or_else(|e| panic!("{e}")).parts);
    let render = |threads: usize, seed: u64| {
        let s = Settings { caustic_photons: 20_000, seed, ..settings(Method::Photon, 1) };
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| render_quiet(&scene, &s))
    };
    let one = render(1, 9);
    assert!(one.pixels.iter().all(|p| p.is_finite()));
    assert_eq!(one, render(2, 9));
    assert_eq!(one, render(3, 9));
    assert_ne!(one, render(2, 10));
    // Progressive passes go on along one sequence: the same too.
    let passes = |threads: usize, seed: u64| {
        let s = Settings { caustic_photons: 5_000, seed, ..settings(Method::Photon, 1) };
        let f = || photonmap::render::render_progressive(&scene, &s, photonmap::render::Budget::passes(3), |_| {}).0;
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
    };
    let one = passes(1, 9);
    assert_eq!(one, passes(2, 9));
    assert_ne!(one, passes(2, 10));
}
