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
    for (name, limit) in [("flat", usize::MAX), ("bvh", 0)] {
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
