//! The Whitted ray tracer (`trace`) against colours computed by hand from
//! the CS475 formula, on scenes small enough to do the arithmetic:
//! rho = m_a C A + sum_lights (m_l C I max(l.n, 0) + m_s S I max(r.v, 0)^m_sp) + m_r C traceRay(bounce).

use glam::Vec3;
use photonmap::film::Film;
use photonmap::integrator::whitted::Whitted;
use photonmap::math::{Color, Ray};
use photonmap::render::render_with;
use photonmap::render::tracers::WhittedTracing;
use photonmap::sampling::{stream, Domain};
use photonmap::scene::file::parse;
use photonmap::scene::Scene;
use photonmap::settings::Settings;
use std::path::Path;

const CAMERA: &str =
    "[camera]\neye = [0, 0, 10]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\nwidth = 8\nheight = 8\n";

/// A unit sphere at the origin, C = (1, 0.5, 0.25), m_a 0.2, m_l 0.6,
/// m_s 0.5, m_sm 0, m_sp 10, ambient A = 0.1, and the given lights/extras.
fn sphere_scene(extra: &str) -> Scene {
    let text = format!(
        "ambient = [0.1, 0.1, 0.1]\n{CAMERA}\
         [materials.ball]\ntype = \"phong\"\ncolor = [1, 0.5, 0.25]\nm_a = 0.2\nm_l = 0.6\nm_s = 0.5\nm_sm = 0\nm_sp = 10\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"ball\"\n{extra}"
    );
    Scene::from_parts(parse(&text, Path::new("test.toml")).unwrap().parts)
}

fn shade(scene: &Scene, depth: u32, origin: Vec3, towards: Vec3) -> Color {
    let whitted = Whitted { scene, max_depth: depth };
    let mut rng = stream(1, Domain::Camera, 0);
    whitted.trace_ray(&Ray::new(origin, (towards - origin).normalize()), None, 0, &mut rng)
}

/// The scene rendered by the Whitted tracer at 32 x 32, 16 samples a pixel.
fn render(scene: &Scene, max_depth: u32) -> Film {
    let settings = Settings { width: 32, height: 32, spp: 16, seed: 7, ..Settings::default() };
    render_with(scene, &settings, &WhittedTracing { max_depth }, photonmap::progress::Mode::Quiet).0
}

fn close(got: Color, want: Color) {
    assert!((got - want).abs().max_element() < 1e-5, "got {got}, want {want}");
}

const C: Color = Color::new(1.0, 0.5, 0.25);
const SUN: &str = "[[lights]]\ntype = \"directional\"\ndirection = [0, 0, -1]\ncolor = [1, 1, 1]\n";

#[test]
fn specular_peak_under_a_directional_light() {
    // Hit (0,0,1), n = l = v = +z: r = l, r.v = 1: the highlight's peak.
    let got = shade(&sphere_scene(SUN), 0, Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    close(got, 0.2 * C * 0.1 + 0.6 * C + Color::splat(0.5));
}

#[test]
fn lambert_and_highlight_at_a_known_normal() {
    // Ray along -x at height 0.6 meets the sphere at (0.8, 0, 0.6):
    // l.n = 0.6; r = 2 (l.n) n - l = (0.96, 0, -0.28); v = +x: r.v = 0.96.
    let got = shade(&sphere_scene(SUN), 0, Vec3::new(5.0, 0.0, 0.6), Vec3::new(0.0, 0.0, 0.6));
    let want = 0.02 * C + 0.6 * C * 0.6 + Color::splat(0.5 * 0.96f32.powf(10.0));
    close(got, want);
}

#[test]
fn only_the_ambient_term_remains_in_shadow() {
    // A small sphere above the top point blocks the sun there; the camera
    // ray comes in from the side so that it does not meet the blocker.
    let blocker = "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 3]\nradius = 0.5\nmaterial = \"ball\"\n";
    let scene = sphere_scene(&format!("{SUN}{blocker}"));
    let got = shade(&scene, 0, Vec3::new(1.0, 0.0, 2.0), Vec3::new(0.0, 0.0, 1.0));
    close(got, 0.02 * C);
    // Without the blocker the same point is lit (Lambert + highlight).
    let lit = shade(&sphere_scene(SUN), 0, Vec3::new(1.0, 0.0, 2.0), Vec3::new(0.0, 0.0, 1.0));
    assert!(lit.x > 0.5, "{lit}");
}

#[test]
fn point_light_falloff_at_a_known_distance() {
    // Light 2 units above the top point; the course's 1 / (d + d0)^falloff.
    for (falloff, dead, scale) in
        [(1.0f32, 1.0f32, 1.0 / 3.0), (2.0, 0.0, 0.25), (0.0, 0.0, 1.0), (2.0, 2.0, 1.0 / 16.0)]
    {
        let light = format!(
            "[[lights]]\ntype = \"point\"\nposition = [0, 0, 3]\ncolor = [1, 1, 1]\nfalloff = {falloff}\ndead_distance = {dead}\n"
        );
        let got = shade(&sphere_scene(&light), 0, Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        close(got, 0.02 * C + scale * (0.6 * C + Color::splat(0.5)));
    }
    // Shadow rays to a point light only count blockers before the light:
    // a sphere beyond it changes nothing.
    let light = "[[lights]]\ntype = \"point\"\nposition = [0, 0, 3]\ncolor = [1, 1, 1]\n";
    let beyond = "[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 4.5]\nradius = 0.5\nmaterial = \"ball\"\n";
    let a = shade(&sphere_scene(light), 0, Vec3::new(3.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 1.0));
    let b = shade(&sphere_scene(&format!("{light}{beyond}")), 0, Vec3::new(3.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 1.0));
    close(a, b);
}

#[test]
fn the_depth_limit_cuts_reflections() {
    // Mirror A (m_r 0.8, C white, nothing else) at the origin; B above it,
    // ambient-only colour 0.5 * 0.2 = 0.1 plus a mirror m_r 0.5 of C 0.5.
    // A ray down between them: A -> B -> A -> B ...
    let text = format!(
        "ambient = [0.2, 0.2, 0.2]\n{CAMERA}\
         [materials.a]\ntype = \"phong\"\ncolor = [1, 1, 1]\nm_r = 0.8\n\
         [materials.b]\ntype = \"phong\"\ncolor = [0.5, 0.5, 0.5]\nm_a = 1\nm_r = 0.5\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"a\"\n\
         [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 4]\nradius = 1\nmaterial = \"b\"\n"
    );
    let scene = Scene::from_parts(parse(&text, Path::new("test.toml")).unwrap().parts);
    let at = |depth| shade(&scene, depth, Vec3::new(0.0, 0.0, 2.5), Vec3::ZERO).x;
    let want = [0.0, 0.08, 0.08, 0.8 * (0.1 + 0.25 * 0.08), 0.8 * (0.1 + 0.25 * 0.08)];
    for (depth, w) in want.iter().enumerate() {
        assert!((at(depth as u32) - w).abs() < 1e-5, "depth {depth}: {} vs {w}", at(depth as u32));
    }
}

#[test]
fn transformed_spheres_are_ellipsoids_with_correct_normals() {
    // Unit sphere scaled (2, 1, 1), turned 90 degrees about z, moved up 3:
    // its long axis lies along y.
    let text = format!(
        "{CAMERA}[materials.m]\ntype = \"phong\"\ncolor = [1, 1, 1]\nm_l = 1\n\
         [[shapes]]\ntype = \"ellipsoid\"\nmaterial = \"m\"\n\
         transform = [{{ scale = [2, 1, 1] }}, {{ rotate = {{ axis = [0, 0, 1], degrees = 90 }} }}, {{ translate = [0, 0, 3] }}]\n"
    );
    let scene = Scene::from_parts(parse(&text, Path::new("test.toml")).unwrap().parts);
    let along_y = scene.intersect(&Ray::new(Vec3::new(0.0, 5.0, 3.0), -Vec3::Y), None).unwrap();
    assert!((along_y.t - 3.0).abs() < 1e-5, "{}", along_y.t);
    assert!((along_y.normal - Vec3::Y).length() < 1e-5);
    let along_x = scene.intersect(&Ray::new(Vec3::new(5.0, 0.0, 3.0), -Vec3::X), None).unwrap();
    assert!((along_x.t - 4.0).abs() < 1e-5, "{}", along_x.t);
    // On the ellipse x^2 + y^2 / 4 = 1 at (sqrt(0.5), sqrt(2)) the normal is
    // along the gradient (2x, y / 2), not along the position.
    let p = Vec3::new(0.5f32.sqrt(), 2.0f32.sqrt(), 3.0);
    let hit = scene.intersect(&Ray::new(p + Vec3::new(3.0, 0.0, 0.0), -Vec3::X), None).unwrap();
    assert!((hit.point - p).length() < 1e-4, "{}", hit.point);
    let want = Vec3::new(2.0 * p.x, p.y / 2.0, 0.0).normalize();
    assert!((hit.normal - want).length() < 1e-4, "{} vs {want}", hit.normal);
}

#[test]
fn jittered_supersampling_averages_an_edge() {
    // A pixel straddling the sphere's silhouette against black: with 4 x 4
    // jittered rays its value lies strictly between black and the lit colour,
    // and the image is the same on 1 and 3 threads.
    let scene = sphere_scene(SUN);
    let run =
        |threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| render(&scene, 0));
    let film = run(1);
    let partial = film.pixels.iter().filter(|c| c.x > 0.01 && c.x < 0.3).count();
    assert!(partial > 8, "{partial} pixels on the silhouette");
    assert!(film.pixels == run(3).pixels, "thread count changed the image");
}

/// Through a thin lens focused far behind the sphere, its silhouette blurs
/// (more pixels between black and lit than through the pinhole), and the
/// lens points, drawn from each pixel's own stream under the jittered
/// grid, leave the image the same on 1 and 3 threads.
#[test]
fn a_thin_lens_blurs_the_silhouette_on_any_thread_count() {
    let scene = |lens: &str| {
        let text = format!(
            "ambient = [0.1, 0.1, 0.1]\n{CAMERA}{lens}\n\
             [materials.ball]\ntype = \"phong\"\ncolor = [1, 0.5, 0.25]\nm_a = 0.2\nm_l = 0.6\n\
             [[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"ball\"\n{SUN}"
        );
        Scene::from_parts(parse(&text, Path::new("lens.toml")).unwrap().parts)
    };
    let (pinhole, lens) = (scene(""), scene("aperture_radius = 0.5\nfocus_distance = 40"));
    let run = |scene: &Scene, threads| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| render(scene, 0))
    };
    let partial = |film: &Film| film.pixels.iter().filter(|c| c.x > 0.01 && c.x < 0.3).count();
    let (sharp, blurred) = (run(&pinhole, 1), run(&lens, 1));
    assert!(partial(&blurred) > 2 * partial(&sharp), "{} vs {}", partial(&blurred), partial(&sharp));
    assert!(blurred.pixels == run(&lens, 3).pixels, "thread count changed the image");
}
