//! Loading a large mesh: the time to read the OBJ and build the scene (its
//! BVH), and the bytes held per triangle, counted by the scene and seen by
//! the process. `cargo run --release --example mesh_load [-- SCENE.toml]`
//! (default: scenes/suite/07-million.toml, a million-triangle glass knot,
//! its mesh made first if missing). Figures: notes/performance.md.

use photonmap::scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

/// Resident memory of this process, in bytes (Linux).
fn resident() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1).and_then(|v| v.parse::<u64>().ok()))
        .map_or(0, |pages| pages * 4096)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let path = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(|| root.join("scenes/suite/07-million.toml"));
    photonmap::scene::procedural::write_suite_meshes(&root.join("scenes/suite/meshes"), true)?;
    let before = resident();
    let t = Instant::now();
    let file = photonmap::scene::file::load(&path)?;
    let read = t.elapsed();
    let scene = Scene::from_parts(file.parts);
    let total = t.elapsed();
    let after = resident();
    let n = scene.prim_count() as f64;
    println!("{}: {} primitives", path.display(), scene.prim_count());
    println!("  read the file (OBJ parse, checks)  {:>7.3} s", read.as_secs_f64());
    println!("  build the scene (BVH)              {:>7.3} s", (total - read).as_secs_f64());
    println!("  total                              {:>7.3} s", total.as_secs_f64());
    println!("  held by the scene                  {:>7.1} bytes per primitive", scene.memory_bytes() as f64 / n);
    println!(
        "  resident growth of the process     {:>7.1} bytes per primitive",
        after.saturating_sub(before) as f64 / n
    );
    Ok(())
}
