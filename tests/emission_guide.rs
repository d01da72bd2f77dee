//! The global pass's guide for light at infinity (src/photon/guide.rs):
//! its cells drawn as its density says (χ²), the photons it sends carrying
//! the natural emission's power in expectation, the guide the same on any
//! number of threads, and no guide in a scene without light at infinity.

mod common;

use common::chi2::Chi2;
use common::scratch_dir;
use glam::{Vec2, Vec3};
use photonmap::photon::guide::EmissionGuide;
use photonmap::photon::trace::{emit, emit_at, Pass};
use photonmap::sampling::{stream, Domain};
use photonmap::scene::{Eye, Scene};

/// A closed room of unit size with an open window in its east wall (y in
/// [0.2, 0.8], z in [0.4, 0.9]), the sun shining in along `SUN`, the camera
/// inside looking at the floor and the west wall.
const ROOM: &str = r#"
[camera]
eye = [0.9, 0.5, 0.8]
target = [0.0, 0.5, 0.1]
up = [0, 0, 1]
vfov = 70
width = 32
height = 32

[materials.wall]
type = "lambertian"
rho = [0.5, 0.5, 0.5]

[[shapes]]
type = "quad"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[1, 0, 0], [1, 0, 1], [1, 0.2, 1], [1, 0.2, 0]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[1, 0.8, 0], [1, 0.8, 1], [1, 1, 1], [1, 1, 0]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[1, 0.2, 0], [1, 0.2, 0.4], [1, 0.8, 0.4], [1, 0.8, 0]]
material = "wall"

[[shapes]]
type = "quad"
vertices = [[1, 0.2, 0.9], [1, 0.2, 1], [1, 0.8, 1], [1, 0.8, 0.9]]
material = "wall"

[[lights]]
type = "directional"
direction = [-1, 0.1, -0.45]
color = [3, 3, 3]
"#;

const SUN: Vec3 = Vec3::new(-1.0, 0.1, -0.45);
const IRRADIANCE: f64 = 3.0;

fn room() -> Scene {
    // A directory per call: the tests run side by side.
    static CALLS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = scratch_dir(&format!("emission_guide_{call}"));
    let path = dir.join("room.toml");
    std::fs::write(&path, ROOM).unwrap();
    let file = photonmap::scene::file::load(&path).unwrap_or_else(|e| panic!("{e}"));
    Scene::from_parts(file.parts)
}

/// The guide of the room's global pass, its pilot judging photons by
/// their first hit alone.
fn guide(scene: &Scene, seed: u64) -> EmissionGuide {
    EmissionGuide::build(scene, false, seed, &|_, _, _, _| Vec::new()).expect("the sun's window is seen")
}

/// The power a photon of the global pass sends in through the window: its
/// power where its ray crosses the wall's plane inside the window, else 0.
fn through_window(ray: &photonmap::math::Ray, power: Vec3) -> f64 {
    let t = (1.0 - ray.origin.x) / ray.dir.x;
    let p = ray.origin + t * ray.dir;
    let inside = t > 0.0 && (0.2..0.8).contains(&p.y) && (0.4..0.9).contains(&p.z);
    if inside {
        power.x as f64
    } else {
        0.0
    }
}

/// The guide draws its cells (here, the sun's 128² cells of the start's
/// square, binned 32 x 32) in proportion to its density.
#[test]
fn guided_starts_follow_their_density() {
    let scene = room();
    let g = guide(&scene, 1);
    let (bins, cells) = (32usize, 128usize);
    let chi2 = Chi2 { samples: 500_000, ..Chi2::default() };
    let mut observed = vec![0f64; bins * bins];
    let mut rng = stream(7, Domain::Camera, 0);
    for _ in 0..chi2.samples {
        let (u, _, w) = g.sample(0, &mut rng).expect("the sun is guided");
        // At most 1 / UNIFORM, but for the f32 resolution of the cells'
        // cumulative chances (the weight divides by the chance drawn).
        assert!(w.is_finite() && w > 0.0 && w <= 1.02 / photonmap::photon::guide::UNIFORM as f32, "{w}");
        let (i, j) = ((u.x * bins as f32) as usize, (u.y * bins as f32) as usize);
        observed[j.min(bins - 1) * bins + i.min(bins - 1)] += 1.0;
    }
    let mut expected = vec![0f64; bins * bins];
    let mut mass = 0.0;
    for y in 0..cells {
        for x in 0..cells {
            let u = (Vec2::new(x as f32, y as f32) + 0.5) / cells as f32;
            let p = g.density(0, u, Vec2::splat(0.5)) as f64 / (cells * cells) as f64;
            mass += p;
            let bin = (y * bins / cells) * bins + x * bins / cells;
            expected[bin] += p * chi2.samples as f64;
        }
    }
    assert!((mass - 1.0).abs() < 1e-4, "the density integrates to {mass}");
    let outcome = chi2.pearson(&observed, &expected, mass);
    assert!(outcome.passed(), "{outcome:?}");
    // It aims: most of its cells' chance lies where the window is.
    let top = expected.iter().filter(|&&e| e > 2.0 * chi2.samples as f64 / (bins * bins) as f64).count();
    assert!(top < bins * bins / 4, "{top} bins above twice the uniform chance");
}

/// The power that guided photons carry in through the window is, in
/// expectation, the natural emission's, and both the sun's irradiance
/// across the window's projection; the guided estimate's variance is far
/// lower (its photons go there).
#[test]
fn guided_photons_carry_the_natural_power_through_the_window() {
    let scene = room();
    let g = guide(&scene, 3);
    let n = 200_000u64;
    let stats = |guided: bool| {
        let (mut sum, mut sq) = (0f64, 0f64);
        for i in 0..n {
            let mut rng = stream(11, Domain::GlobalPhotons, i);
            let start = match guided {
                true => emit_at(&scene, &[], Pass::Global, n, None, Some(&g), &mut rng).1,
                false => emit(&scene, &[], Pass::Global, n, &mut rng).1,
            };
            let v = start.map_or(0.0, |(ray, _, power)| through_window(&ray, power)) * n as f64;
            sum += v;
            sq += v * v;
        }
        let mean = sum / n as f64;
        (mean, ((sq / n as f64 - mean * mean) / n as f64).sqrt())
    };
    let d = SUN.normalize();
    let exact = IRRADIANCE * 0.6 * 0.5 * d.x.abs() as f64;
    let (natural, se_natural) = stats(false);
    let (guided, se_guided) = stats(true);
    println!("through the window: exact {exact}, natural {natural} ± {se_natural}, guided {guided} ± {se_guided}");
    assert!((natural - exact).abs() < 4.0 * se_natural, "natural {natural} ± {se_natural} vs {exact}");
    assert!((guided - exact).abs() < 4.0 * se_guided, "guided {guided} ± {se_guided} vs {exact}");
    assert!(se_guided < se_natural / 3.0, "guided ± {se_guided}, natural ± {se_natural}");
}

/// The guide is the same whatever the number of threads that build it.
#[test]
fn the_guide_is_the_same_on_any_number_of_threads() {
    let scene = room();
    let on = |threads| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            let g = guide(&scene, 5);
            let mut rng = stream(1, Domain::Camera, 0);
            (0..1000).map(|_| g.sample(0, &mut rng).unwrap()).collect::<Vec<_>>()
        })
    };
    assert_eq!(on(1), on(3));
}

/// A scene without light at infinity builds no guide: its photons, and
/// the default room's image, are as before.
#[test]
fn a_scene_lit_from_inside_has_no_guide() {
    let scene = Scene::tncg15(Eye::One);
    assert!(EmissionGuide::build(&scene, false, 1, &|_, _, _, _| Vec::new()).is_none());
}

/// A guided global pass stores the same photons on any number of threads,
/// and stores some in the room (the guide sends them through the window).
#[test]
fn a_guided_pass_is_the_same_on_any_number_of_threads() {
    let scene = room();
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| photonmap::photon::trace::trace_pass(&scene, Pass::Global, 20_000, 5, &|_| {}).photons)
    };
    let one = on(1);
    assert!(one.len() > 100, "{} photons stored", one.len());
    assert_eq!(one, on(3));
}

/// A guided global pass asked for n emits no more than n (the natural
/// emission's count), and enough that at least a quarter of n come into
/// the room through the window, which the natural emission's n do not
/// (the window is a small part of the disk over the scene).
#[test]
fn a_guided_pass_lands_a_quarter_of_what_is_asked() {
    let scene = room();
    let n = 20_000u64;
    let emitted = photonmap::photon::trace::trace_pass(&scene, Pass::Global, n, 5, &|_| {}).emitted;
    let g = guide(&scene, 5);
    let samples = 4000;
    let (mut guided, mut natural) = (0u32, 0u32);
    for i in 0..samples {
        let mut rng = stream(9, Domain::GlobalPhotons, i);
        let (_, start) = emit_at(&scene, &[], Pass::Global, n, None, Some(&g), &mut rng);
        let (ray, _, power) = start.unwrap();
        guided += (through_window(&ray, power) > 0.0) as u32;
        let mut rng = stream(9, Domain::GlobalPhotons, i);
        let (_, start) = emit(&scene, &[], Pass::Global, n, &mut rng);
        let (ray, _, power) = start.unwrap();
        natural += (through_window(&ray, power) > 0.0) as u32;
    }
    let landing = |count: u32, emitted: u64| emitted as f64 * count as f64 / samples as f64;
    assert!(emitted <= n, "{emitted} emitted of {n} asked");
    assert!(landing(natural, n) < 0.25 * n as f64, "the natural emission lands {}", landing(natural, n));
    let landed = landing(guided, emitted);
    assert!(landed > 0.22 * n as f64, "{landed} of {n} land through the window ({emitted} emitted)");
}
