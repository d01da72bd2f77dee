//! Loading a scene file of many entries: scenes/tncg15.toml with N small
//! spheres appended (radius 0.02, material "grey", on a grid inside the
//! room), timed as read and checked (`scene::file::load`) and as built
//! (`Scene::from_parts`, the BVH). Loading must grow linearly with N.
//! `cargo run --release --example scene_load [-- N...]` (default: 10000
//! 50000 100000). Figures: notes/performance.md.

use photonmap::scene::Scene;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let counts: Vec<usize> = match std::env::args().skip(1).map(|a| a.parse::<f64>()).collect::<Result<Vec<_>, _>>()? {
        v if v.is_empty() => vec![10_000, 50_000, 100_000],
        v => v.into_iter().map(|n| n as usize).collect(),
    };
    let base = std::fs::read_to_string(root.join("scenes/tncg15.toml"))?;
    let dir = std::env::temp_dir().join(format!("photonmap-scene-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    println!("{:>8} {:>10} {:>10} {:>10} {:>12}", "spheres", "read (s)", "build (s)", "total (s)", "µs / sphere");
    for n in counts {
        let mut text = base.clone();
        for i in 0..n {
            // A grid of 50 x 50 x k points inside the room (x 1..11, y -5..5, z -4..4).
            let (a, b, c) = (i % 50, (i / 50) % 50, i / 2500);
            let center = [1.5 + 0.18 * a as f32, -4.5 + 0.18 * b as f32, -3.5 + 0.15 * (c % 48) as f32];
            writeln!(
                text,
                "\n[[shapes]]\ntype = \"sphere\"\ncenter = [{}, {}, {}]\nradius = 0.02\nmaterial = \"grey\"",
                center[0], center[1], center[2]
            )?;
        }
        let path = dir.join(format!("spheres-{n}.toml"));
        std::fs::write(&path, &text)?;
        let t = Instant::now();
        let file = photonmap::scene::file::load(&path)?;
        let read = t.elapsed().as_secs_f64();
        let scene = Scene::from_parts(file.parts);
        let total = t.elapsed().as_secs_f64();
        assert!(scene.prim_count() >= n);
        println!("{n:>8} {read:>10.3} {:>10.3} {total:>10.3} {:>12.2}", total - read, 1e6 * total / n as f64);
        std::fs::remove_file(&path)?;
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
