//! Rays per second of the default scene's accelerator, flat loop vs BVH:
//! `cargo run --release --example raycast`.
use photonmap::accel::Accel;
use photonmap::math::Ray;
use photonmap::sampling::{next_2d, stream, uniform_cone, Domain};
use photonmap::scene::{Eye, Scene};
use std::time::Instant;

fn main() {
    let scene = Scene::tncg15(Eye::One);
    let shapes: Vec<_> = scene.prims.iter().map(|p| p.shape).collect();
    let mut rng = stream(1, Domain::Camera, 0);
    let rays: Vec<Ray> = (0..2_000_000)
        .map(|_| {
            let u = next_2d(&mut rng);
            let o = glam::Vec3::new(-2.0 + 14.0 * u.x, -5.0 + 10.0 * u.y, -4.5 + 9.0 * next_2d(&mut rng).x);
            Ray::new(o, uniform_cone(next_2d(&mut rng), -1.0))
        })
        .collect();
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
    for (name, limit) in [("flat, watertight", usize::MAX), ("bvh, watertight", 0)] {
        let accel = Accel::with_flat_limit(shapes.clone(), limit);
        let t = Instant::now();
        let hits = rays.iter().filter(|r| accel.closest_hit(r, None, f32::INFINITY).is_some()).count();
        let dt = t.elapsed().as_secs_f64();
        println!(
            "{name}: {:.1} ns/ray, {:.2} M rays/s/thread, {hits} hits",
            dt / rays.len() as f64 * 1e9,
            rays.len() as f64 / dt / 1e6
        );
    }
}
