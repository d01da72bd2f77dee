//! The floors of notes/performance.md, measured on this machine, 1 thread:
//! the cost of one ray in the default scene (random rays in the room, and
//! the camera's primary rays), a sort of as many 32-byte photons as the
//! global map holds by a 64-bit key (the kd-tree build's floor), and the
//! bandwidth of streaming them (a lookup's floor per photon read).
//! `cargo run --release --example floors`
use photonmap::math::Ray;
use photonmap::photon::Photon;
use photonmap::sampling::{random_rays, splitmix64};
use photonmap::scene::{Eye, Scene};
use std::time::Instant;

fn main() {
    let scene = Scene::tncg15(Eye::One);
    let random = random_rays(glam::Vec3::new(-2.0, -5.0, -4.5), glam::Vec3::new(12.0, 5.0, 4.5), 1_000_000, 1);
    let cam = scene.camera;
    let primary: Vec<Ray> = (0..800 * 800).map(|i| cam.ray(i % 800, i / 800, glam::Vec2::splat(0.5))).collect();
    for (name, rays) in [("random rays in the room", &random), ("primary camera rays", &primary)] {
        let t = Instant::now();
        let hits = rays.iter().filter(|r| scene.intersect(r, None).is_some()).count();
        let dt = t.elapsed().as_secs_f64();
        println!("closest hit, {name}: {:.0} ns per ray ({hits} hits)", dt / rays.len() as f64 * 1e9);
        let t = Instant::now();
        let blocked = rays.iter().filter(|r| scene.occluded(r, None, 3.0, None)).count();
        let dt = t.elapsed().as_secs_f64();
        println!("occlusion to t = 3, {name}: {:.0} ns per ray ({blocked} blocked)", dt / rays.len() as f64 * 1e9);
    }
    let n = 4_917_159; // global photons stored at 1e6 emitted
    let mut photons: Vec<(u64, Photon)> = (0..n as u64).map(|i| (splitmix64(i), Photon::default())).collect();
    let t = Instant::now();
    photons.sort_unstable_by_key(|p| p.0);
    println!("sort of {n} photons (40 bytes with the key) by a 64-bit key: {:.0} ms", t.elapsed().as_secs_f64() * 1e3);
    let m = 985_677; // photons in the kd_tree_build bench
    let mut small: Vec<(u64, Photon)> = (0..m as u64).map(|i| (splitmix64(i), Photon::default())).collect();
    let t = Instant::now();
    small.sort_unstable_by_key(|p| p.0);
    println!("sort of {m} photons by a 64-bit key: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let t = Instant::now();
    let mut sum = 0.0f32;
    for _ in 0..10 {
        sum += photons.iter().map(|p| p.1.power[0] + p.1.pos[1]).sum::<f32>();
    }
    let dt = t.elapsed().as_secs_f64() / 10.0;
    let bytes = (n * std::mem::size_of::<(u64, Photon)>()) as f64;
    println!("streaming read: {:.1} GB/s, {:.2} ns per photon ({sum})", bytes / dt / 1e9, dt / n as f64 * 1e9);
}
