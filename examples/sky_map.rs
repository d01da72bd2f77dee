//! Writes the environment map of suite scene 11,
//! scenes/suite/maps/sky.hdr: a clear sky over a dim ground, a small sun
//! 35 degrees high with a glow about it. `cargo run --release --example
//! sky_map` (the file is committed; this says how it was made).
//!
//! The map is in Mitsuba's frame (src/envmap.rs): +y is up, u = 0 looks
//! along -z, rows sit at v = y / (height - 1); 11-envmap-glass.toml turns
//! its +y to the scene's +z. Each texel is the mean of the sky over 8 x 8
//! points of its cell in (u, v), so the sun's rim is spread over the
//! texels it crosses rather than cut at their centres.
//!
//! The sun is a disc 5 degrees across (ten times the real sun's) of
//! radiance 1,400: an irradiance of 8.4 across its beam, against about 2.3
//! from the sky on the ground. A smaller, brighter sun focuses sharper,
//! but a path tracer, the reference, finds the caustic only where a path
//! from the floor happens to pass through the ball onto the sun: its
//! noise there grows as the sun's radiance (at radiance 20,000 and 1.5
//! degrees, Mitsuba's whole image had an RMSE of 4 at 64 spp).

use glam::Vec3;
use photonmap::film::Film;
use std::f32::consts::PI;

const WIDTH: u32 = 512;
const HEIGHT: u32 = 256;
/// The sun's elevation and its azimuth from -z towards +x, in degrees,
/// and its angular radius.
const SUN_ELEVATION: f32 = 35.0;
const SUN_AZIMUTH: f32 = 25.0;
const SUN_RADIUS: f32 = 2.5;
const SUN: Vec3 = Vec3::new(1_400.0, 1_330.0, 1_230.0);

/// The unit direction (map frame) of texture coordinates (u, v), as the
/// map reads them: theta = pi v from +y, phi = 2 pi u from -z towards +x.
fn direction(u: f32, v: f32) -> Vec3 {
    let (theta, phi) = (v * PI, u * 2.0 * PI);
    Vec3::new(phi.sin() * theta.sin(), theta.cos(), -phi.cos() * theta.sin())
}

fn sun_direction() -> Vec3 {
    let (e, a) = (SUN_ELEVATION.to_radians(), SUN_AZIMUTH.to_radians());
    Vec3::new(a.sin() * e.cos(), e.sin(), -a.cos() * e.cos())
}

/// Radiance arriving from map direction `d`.
fn sky(d: Vec3, sun: Vec3) -> Vec3 {
    let angle = d.dot(sun).clamp(-1.0, 1.0).acos();
    if angle < SUN_RADIUS.to_radians() {
        return SUN;
    }
    let elevation = d.y.clamp(-1.0, 1.0).asin();
    if elevation < 0.0 {
        // A dim ground, darker straight down.
        return Vec3::new(0.14, 0.12, 0.10) * (1.0 + 0.5 * d.y);
    }
    let horizon = Vec3::new(0.95, 1.0, 1.1);
    let zenith = Vec3::new(0.22, 0.40, 0.85);
    let t = (elevation / (0.5 * PI)).sqrt();
    let glow = Vec3::new(1.0, 0.85, 0.6) * (2.5 * (-angle / 0.12).exp() + 0.3 * (-angle / 0.6).exp());
    horizon.lerp(zenith, t) * 0.7 + glow
}

fn main() -> std::io::Result<()> {
    let sun = sun_direction();
    let n = 8;
    let mut pixels = Vec::with_capacity((WIDTH * HEIGHT) as usize);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let mut sum = Vec3::ZERO;
            for j in 0..n {
                for i in 0..n {
                    let u = (x as f32 + (i as f32 + 0.5) / n as f32) / WIDTH as f32;
                    // Rows sit at v = y / (height - 1), the first and
                    // last at the poles, as the map reads them.
                    let v = ((y as f32 + (j as f32 + 0.5) / n as f32 - 0.5) / (HEIGHT - 1) as f32).clamp(0.0, 1.0);
                    sum += sky(direction(u, v), sun);
                }
            }
            pixels.push(sum / (n * n) as f32);
        }
    }
    let film = Film { width: WIDTH, height: HEIGHT, pixels };
    let bytes = photonmap::output::hdr_bytes(&film).map_err(std::io::Error::other)?;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/maps");
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("sky.hdr");
    std::fs::write(&path, &bytes)?;
    println!("wrote {} ({} bytes)", path.display(), bytes.len());
    Ok(())
}
