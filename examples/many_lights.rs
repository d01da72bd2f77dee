//! Many lights against few: what a render costs at equal error.
//!
//! `cargo build --release && cargo run --release --example many_lights
//! [-- --bin PATH] [--runs N] [--refs DIR]`. Scenes, written as scene
//! files into a temporary directory (or `--refs DIR`, where the
//! references are kept between runs): the default room with its two
//! spheres made diffuse (what is measured is light reaching diffuse
//! surfaces, not lights seen in mirrors), lit by
//!
//! - `one`: its disk light (radius 1, radiance 10);
//! - `100 packed`, `1000 packed`: 100 disks of radius 0.08, 1,000 of
//!   radius 0.025, on a grid within that disk, of the same total power;
//! - `quad`: one rectangle of light (two triangles) over the ceiling
//!   (x 1..10, y -5..5), the same power;
//! - `1000 spread`: 1,000 disks of radius 0.05 on a 40 x 25 grid over that
//!   rectangle, the same power;
//! - `rect + mesh`: a rectangle of light 4 x π/4 (two triangles) just below
//!   a 100,352-triangle mesh of the same rectangle that does not emit;
//! - `8 + mesh`: the same with the rectangle in four (eight triangles, a
//!   few lights, each visited by every shadow-ray estimate);
//! - `mesh`: that mesh emitting, each triangle a light, the same power.
//!
//! Each scene is rendered `--runs` times (default 3; seeds 1, 2, ...;
//! the scenes interleaved) by the photonmap binary (`--bin`, default
//! target/release/photonmap) at 100 x 100 with 1e5 photons, timed from
//! start to exit, and scored against its own reference (1e6 photons, 64
//! spp, seed 7) by the relative MSE over the pixels that do not see a
//! light (reference below 1). The cost at equal error is the median time
//! times the mean relative MSE (for noise, error² falls as 1 / time); each
//! is given against the scene of few lights it stands beside. Figures:
//! notes/performance.md.

use photonmap::output::read_exr;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The default room's text up to its light, its spheres diffuse.
fn room(root: &Path) -> Result<String, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(root.join("scenes/tncg15.toml"))?;
    let head = &text[..text.find("[[lights]]").ok_or("no [[lights]] in scenes/tncg15.toml")?];
    Ok(head
        .replace("material = \"glass\"", "material = \"grey\"")
        .replace("material = \"mirror\"", "material = \"grey\""))
}

fn disk(text: &mut String, x: f64, y: f64, radius: f64, radiance: f64) {
    let _ = write!(
        text,
        "\n[[lights]]\ntype = \"disk\"\ncenter = [{x:.5}, {y:.5}, 4.999]\nnormal = [0, 0, -1]\nradius = {radius}\nradiance = [{radiance:.5}, {radiance:.5}, {radiance:.5}]\n"
    );
}

/// A mesh of `nx` x `ny` x 2 triangles over the rectangle at height `z`,
/// facing down, written to `path`.
fn grid(path: &Path, (x0, x1, y0, y1): (f64, f64, f64, f64), z: f64, nx: usize, ny: usize) -> std::io::Result<()> {
    let mut obj = String::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (x0 + (x1 - x0) * i as f64 / nx as f64, y0 + (y1 - y0) * j as f64 / ny as f64);
            let _ = writeln!(obj, "v {x:.6} {y:.6} {z}");
        }
    }
    for j in 0..ny {
        for i in 0..nx {
            let a = j * (nx + 1) + i + 1;
            let (b, c) = (a + 1, a + nx + 1);
            let _ = writeln!(obj, "f {a} {c} {b}\nf {b} {c} {}", c + 1);
        }
    }
    std::fs::write(path, obj)
}

fn mesh_entry(file: &str, what: &str) -> String {
    format!("\n[[shapes]]\ntype = \"mesh\"\nfile = \"{file}\"\n{what}\n")
}

/// The scenes: (name, file, the scene of few lights it is set against).
/// A benchmark scene: its name, its file, the scene of few lights it is
/// set against.
type Bench = (&'static str, PathBuf, usize);

fn scenes(root: &Path, dir: &Path) -> Result<Vec<Bench>, Box<dyn std::error::Error>> {
    let head = room(root)?;
    let pi = std::f64::consts::PI;
    let mut out = Vec::new();
    let mut put = |name: &'static str, text: String, against: usize| -> std::io::Result<()> {
        let path = dir.join(format!("{}.toml", name.replace(' ', "-").replace('+', "and")));
        std::fs::write(&path, text)?;
        out.push((name, path, against));
        Ok(())
    };
    // The default light: power π² 10.
    let mut one = head.clone();
    disk(&mut one, 8.0, 0.0, 1.0, 10.0);
    put("one", one, 0)?;
    // 100 disks on an 11 x 11 grid, and 1,000 on a 37 x 37 grid, those
    // nearest the centre.
    for (name, count, side, radius) in [("100 packed", 100, 11, 0.08), ("1000 packed", 1000, 37, 0.025)] {
        let mut points: Vec<(f64, f64)> = (0..side * side)
            .map(|k| {
                (
                    -1.0 + 2.0 * ((k % side) as f64 + 0.5) / side as f64,
                    -1.0 + 2.0 * ((k / side) as f64 + 0.5) / side as f64,
                )
            })
            .collect();
        points.sort_by(|a, b| (a.0 * a.0 + a.1 * a.1).total_cmp(&(b.0 * b.0 + b.1 * b.1)));
        let mut packed = head.clone();
        for &(x, y) in &points[..count] {
            disk(&mut packed, 8.0 + x, y, radius, 10.0 / (count as f64 * radius * radius));
        }
        put(name, packed, 0)?;
    }
    let ceiling = (1.0, 10.0, -5.0, 5.0);
    grid(&dir.join("quad.obj"), ceiling, 4.999, 1, 1)?;
    put("quad", head.clone() + &mesh_entry("quad.obj", &format!("emission = [{0}, {0}, {0}]", pi * 10.0 / 90.0)), 3)?;
    let mut spread = head.clone();
    for k in 0..1000 {
        let (x, y) = (1.0 + 9.0 * ((k % 40) as f64 + 0.5) / 40.0, -5.0 + 10.0 * ((k / 40) as f64 + 0.5) / 25.0);
        disk(&mut spread, x, y, 0.05, 10.0 / (1000.0 * 0.05 * 0.05));
    }
    put("1000 spread", spread, 3)?;
    // A rectangle of area π: the default light's power at radiance 10.
    let rect = (6.0, 10.0, -pi / 8.0, pi / 8.0);
    grid(&dir.join("grid.obj"), rect, 4.999, 224, 224)?;
    grid(&dir.join("rect.obj"), rect, 4.998, 1, 1)?;
    grid(&dir.join("rect4.obj"), rect, 4.998, 2, 2)?;
    let under =
        |lights: &str| mesh_entry("grid.obj", "material = \"grey\"") + &mesh_entry(lights, "emission = [10, 10, 10]");
    put("rect + mesh", head.clone() + &under("rect.obj"), 5)?;
    put("8 + mesh", head.clone() + &under("rect4.obj"), 6)?;
    put("mesh", head + &mesh_entry("grid.obj", "emission = [10, 10, 10]"), 6)?;
    Ok(out)
}

/// Luminance per pixel of an EXR.
fn pixels(path: &Path) -> Result<Vec<[f64; 3]>, Box<dyn std::error::Error>> {
    let film = read_exr(path)?;
    Ok(film.pixels.iter().map(|c| [c.x as f64, c.y as f64, c.z as f64]).collect())
}

/// The relative MSE of `test` against `reference` over the pixels whose
/// reference is below 1 (that see no light).
fn rel_mse(test: &Path, reference: &[[f64; 3]]) -> Result<f64, Box<dyn std::error::Error>> {
    let t = pixels(test)?;
    let (mut sum, mut count) = (0.0, 0);
    for (a, r) in t.iter().zip(reference) {
        if (r[0] + r[1] + r[2]) / 3.0 > 1.0 {
            continue;
        }
        sum += (0..3).map(|c| (a[c] - r[c]).powi(2) / (r[c] * r[c] + 1e-2)).sum::<f64>() / 3.0;
        count += 1;
    }
    Ok(sum / count.max(1) as f64)
}

fn run(bin: &Path, scene: &Path, out: &Path, args: &[&str]) -> Result<f64, Box<dyn std::error::Error>> {
    let t = Instant::now();
    let status = Command::new(bin)
        .args(["--scene", scene.to_str().ok_or("path")?, "--width", "100", "--height", "100", "-q"])
        .args(args)
        .arg(out)
        .status()?;
    if !status.success() {
        return Err(format!("{} failed on {}", bin.display(), scene.display()).into());
    }
    Ok(t.elapsed().as_secs_f64())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let value = |f: &str| args.windows(2).find(|w| w[0] == f).map(|w| w[1].clone());
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let bin = value("--bin").map_or_else(|| root.join("target/release/photonmap"), PathBuf::from);
    let runs: usize = value("--runs").map_or(Ok(3), |r| r.parse())?;
    let dir = value("--refs").map_or_else(
        || std::env::temp_dir().join(format!("photonmap-many-lights-{}", std::process::id())),
        PathBuf::from,
    );
    std::fs::create_dir_all(&dir)?;
    let scenes = scenes(&root, &dir)?;
    let mut references = Vec::new();
    for (name, path, _) in &scenes {
        let reference = path.with_extension("ref.exr");
        if !reference.exists() {
            eprintln!("reference of {name} ...");
            run(&bin, path, &reference, &["--photons", "1e6", "--spp", "64", "--seed", "7"])?;
        }
        references.push(pixels(&reference)?);
    }
    let mut times = vec![Vec::new(); scenes.len()];
    let mut errors = vec![Vec::new(); scenes.len()];
    for r in 0..runs {
        for (k, (name, path, _)) in scenes.iter().enumerate() {
            let out = dir.join(format!("test-{k}.exr"));
            let seed = (r + 1).to_string();
            times[k].push(run(&bin, path, &out, &["--photons", "1e5", "--seed", &seed])?);
            errors[k].push(rel_mse(&out, &references[k])?);
            eprintln!("{name} run {r}: {:.3} s, relMSE {:.5}", times[k][r], errors[k][r]);
        }
    }
    println!("{}", bin.display());
    println!("{:<12} {:>10} {:>10} {:>12} {:>10}", "scene", "time (s)", "relMSE", "t x relMSE", "against");
    let cost = |k: usize| {
        let mut t = times[k].clone();
        t.sort_by(f64::total_cmp);
        let median = t[t.len() / 2];
        let error = errors[k].iter().sum::<f64>() / errors[k].len() as f64;
        (median, error, median * error)
    };
    for (k, (name, _, against)) in scenes.iter().enumerate() {
        let (t, e, c) = cost(k);
        let ratio = if *against == k {
            String::from("-")
        } else {
            format!("{:.2}x {}", c / cost(*against).2, scenes[*against].0)
        };
        println!("{name:<12} {t:>10.3} {e:>10.5} {c:>12.6} {ratio:>10}");
    }
    Ok(())
}
