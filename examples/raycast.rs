//! Rays per second of the default scene's accelerator, flat loop vs BVH:
//! `cargo run --release --example raycast`; `-- --mesh`: the 100k-triangle
//! mesh scene, BVH against the flat loop.
use glam::Vec3;
use photonmap::accel::Accel;
use photonmap::math::Ray;
use photonmap::sampling::{next_2d, random_rays, stream, Domain};
use photonmap::scene::{Eye, Scene};
use photonmap::shape::{Shape, Triangle};
use std::time::Instant;

fn main() {
    if std::env::args().any(|a| a == "--mesh") {
        return mesh_scene();
    }
    let scene = Scene::tncg15(Eye::One);
    let shapes: Vec<_> = (0..scene.prim_count() as u32).map(|i| scene.shape(i).clone()).collect();
    let rays = random_rays(Vec3::new(-2.0, -5.0, -4.5), Vec3::new(12.0, 5.0, 4.5), 2_000_000, 1);
    // The course's Möller–Trumbore over the same primitives (spheres and the
    // disk through their own tests), to price the watertight test.
    let t = Instant::now();
    let mut mt_hits = 0;
    for r in &rays {
        let mut best = f32::INFINITY;
        for s in &shapes {
            let t = match s {
                photonmap::shape::Shape::Triangle(tri) => tri.moller_trumbore(r, best).map(|h| h.0),
                other => other.intersect(r, best, None).map(|h| h.t),
            };
            if let Some(t) = t {
                best = t;
            }
        }
        mt_hits += best.is_finite() as usize;
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "flat, Möller–Trumbore: {:.1} ns/ray, {:.2} M rays/s/thread, {mt_hits} hits",
        dt / rays.len() as f64 * 1e9,
        rays.len() as f64 / dt / 1e6
    );
    // The renderer's own: the room as an enclosure, a BVH over the rest.
    let group = vec![Some(0); shapes.len()];
    let accels = [
        ("flat, watertight", Accel::with_flat_limit(shapes.clone(), usize::MAX)),
        ("bvh, watertight", Accel::with_flat_limit(shapes.clone(), 0)),
        ("enclosure + bvh (the renderer's)", Accel::with_enclosure(shapes.clone(), &group)),
    ];
    for (name, accel) in accels {
        let t = Instant::now();
        let hits = rays.iter().filter(|r| accel.closest_hit(r, None, f32::INFINITY).is_some()).count();
        let dt = t.elapsed().as_secs_f64();
        println!(
            "{name}: {:.1} ns/ray, {:.2} M rays/s/thread, {hits} hits",
            dt / rays.len() as f64 * 1e9,
            rays.len() as f64 / dt / 1e6
        );
        let tests: u64 = rays.iter().map(|r| accel.count_tests(r)).sum();
        println!("  {:.1} primitives tested per ray", tests as f64 / rays.len() as f64);
    }
}

/// The 100k-triangle scene of notes/performance.md: a glass torus of
/// 250 x 200 x 2 triangles standing in the default room, camera rays from
/// eye 1 and random rays, with the BVH and without it (a flat loop).
fn mesh_scene() {
    let scene = Scene::tncg15(Eye::One);
    let mut shapes: Vec<Shape> = (0..scene.prim_count() as u32).map(|i| scene.shape(i).clone()).collect();
    let torus = photonmap::scene::procedural::torus(glam::Vec3::new(8.0, 0.0, -2.0), 2.2, 0.8, 250, 200).triangles();
    shapes.extend(torus.iter().map(|[a, b, c]| Shape::Triangle(Triangle::new(*a, *b, *c))));
    println!("\nmesh scene: {} primitives (100,000 torus triangles + the room)", shapes.len());
    let camera = scene.camera.with_resolution(400, 400);
    let mut rng = stream(2, Domain::Camera, 0);
    let camera_rays: Vec<Ray> = (0..400 * 400).map(|i| camera.ray(i % 400, i / 400, next_2d(&mut rng))).collect();
    let random = random_rays(Vec3::new(-2.0, -5.0, -4.5), Vec3::new(12.0, 5.0, 4.5), 160_000, 3);
    let t = Instant::now();
    let bvh = Accel::new(shapes.clone());
    println!("BVH build (binned SAH, serial): {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let enclosed = Accel::with_enclosure(shapes.clone(), &vec![Some(0); shapes.len()]);
    let flat = Accel::with_flat_limit(shapes, usize::MAX);
    for (kind, rays) in [("camera", &camera_rays), ("random", &random)] {
        let mut rates = Vec::new();
        for (name, accel, n) in
            [("bvh", &bvh, rays.len()), ("flat", &flat, 2_000), ("enclosure + bvh", &enclosed, rays.len())]
        {
            let t = Instant::now();
            let hits = rays[..n].iter().filter(|r| accel.closest_hit(r, None, f32::INFINITY).is_some()).count();
            let dt = t.elapsed().as_secs_f64();
            rates.push(n as f64 / dt);
            println!("{kind} rays, {name}: {:.3} M rays/s/thread ({n} rays, {hits} hits)", n as f64 / dt / 1e6);
        }
        println!("{kind} rays: BVH / flat = {:.0}x", rates[0] / rates[1]);
        // Both find the same nearest hits.
        for r in &rays[..2_000] {
            let (a, b) = (bvh.closest_hit(r, None, f32::INFINITY), flat.closest_hit(r, None, f32::INFINITY));
            assert_eq!(a.map(|h| h.0), b.map(|h| h.0));
        }
    }
}
