//! Writes the scene suite's meshes into scenes/suite/meshes/ (those
//! missing): `cargo run --release --example suite_meshes [-- --large]`.
//! `--large` adds the million-triangle knot of scenes/suite/07-million.toml
//! (about 80 MB, not kept in the repository; the suite's tests and runner
//! make it when they need it).

fn main() -> std::io::Result<()> {
    let large = std::env::args().any(|a| a == "--large");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/meshes");
    let written = photonmap::scene::procedural::write_suite_meshes(&dir, large)?;
    for name in &written {
        println!("wrote {}", dir.join(name).display());
    }
    if written.is_empty() {
        println!("{} holds every mesh already", dir.display());
    }
    Ok(())
}
