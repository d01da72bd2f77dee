//! Writes the smoke of suite scene 14, scenes/suite/maps/smoke.vol
//! (Mitsuba's grid-volume format, one channel, 48³ cells over the unit
//! cube): a plume rising from a source near the bottom, widening and
//! drifting as it rises, its density broken up by a few octaves of value
//! noise so that it has dense puffs and thin wisps. `cargo run --release
//! --example smoke_volume` (the file is committed; this says how it was
//! made). Values lie in [0, 1]: the scene's `scale` sets the extinction.

use photonmap::medium::VolGrid;
use std::path::Path;

const RES: u32 = 48;

/// A hash of a lattice point into [0, 1): the value noise's lattice values.
fn lattice(x: i32, y: i32, z: i32, seed: u32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8DA6_B343)
        ^ (y as u32).wrapping_mul(0xD816_3841)
        ^ (z as u32).wrapping_mul(0xCB1A_B31F)
        ^ seed.wrapping_mul(0x9E37_79B9);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297A_2D39);
    h ^= h >> 15;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Value noise: the lattice values interpolated with a smoothstep.
fn noise(p: [f32; 3], seed: u32) -> f32 {
    let f = p.map(f32::floor);
    let i = f.map(|v| v as i32);
    let t = [p[0] - f[0], p[1] - f[1], p[2] - f[2]].map(|v| v * v * (3.0 - 2.0 * v));
    let mut sum = 0.0;
    for corner in 0..8 {
        let d = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let w: f32 = (0..3).map(|a| if d[a] == 1 { t[a] } else { 1.0 - t[a] }).product();
        sum += w * lattice(i[0] + d[0], i[1] + d[1], i[2] + d[2], seed);
    }
    sum
}

/// Four octaves, in [0, 1].
fn fbm(p: [f32; 3]) -> f32 {
    let (mut sum, mut amp, mut freq, mut norm) = (0.0, 1.0, 1.0, 0.0);
    for octave in 0..4 {
        sum += amp * noise(p.map(|v| v * freq), octave);
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / norm
}

/// The smoke's density at a point of the unit cube (y up).
fn density(p: [f32; 3]) -> f32 {
    let [x, y, z] = p;
    // The plume's axis drifts and sways as it rises; its radius grows.
    let cx = 0.5 + 0.12 * y + 0.05 * (7.0 * y).sin();
    let cz = 0.5 + 0.04 * (5.0 * y + 1.0).cos();
    let radius = 0.08 + 0.25 * y;
    let r2 = ((x - cx).powi(2) + (z - cz).powi(2)) / (radius * radius);
    let column = (-2.0 * r2).exp();
    // Fading in above the source and out towards the top.
    let rise = ((y - 0.05) / 0.1).clamp(0.0, 1.0) * ((0.95 - y) / 0.25).clamp(0.0, 1.0);
    let n = fbm([3.0 * x, 3.0 * y - 0.7, 3.0 * z]);
    let puffs = ((n - 0.35) / 0.45).clamp(0.0, 1.0);
    (column * rise * (0.25 + 0.75 * puffs)).clamp(0.0, 1.0)
}

fn main() {
    let n = RES as usize;
    let mut data = Vec::with_capacity(n * n * n);
    for zi in 0..n {
        for yi in 0..n {
            for xi in 0..n {
                let c = |i: usize| (i as f32 + 0.5) / n as f32;
                data.push(density([c(xi), c(yi), c(zi)]));
            }
        }
    }
    let grid = VolGrid { res: [RES; 3], channels: 1, bbox: ([0.0; 3], [1.0; 3]), data };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/maps/smoke.vol");
    std::fs::write(&path, grid.to_bytes()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    println!("{}: {} cells, largest {}", path.display(), grid.data.len(), grid.max());
}
