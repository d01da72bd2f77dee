//! Outputs are never lost and never destroy an input: one test per rule.
//! An output that is also an input is refused; an output that cannot be
//! written is refused before any rendering; a read-only file is not
//! replaced; Ctrl-C in a progressive render keeps the passes done; no run
//! leaves a temporary file; `.ppm` is binary PPM; the EXR says how it was
//! made; other image sizes keep the picture's aspect.

mod common;
use common::{photonmap, scratch_dir};
use photonmap::output::read_header;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

const TINY: &[&str] = &["--width", "16", "--height", "16", "--photons", "1e3", "--caustic-photons", "1e3", "--quiet"];

/// Settings whose render takes minutes: a refusal that comes back at once
/// was made before rendering.
const HEAVY: &[&str] = &["--photons", "3e7", "--caustic-photons", "3e7", "--width", "2000", "--height", "2000"];

fn refused_at_once(args: &[&str], message: &str) {
    let start = Instant::now();
    let o = photonmap(&[HEAVY, args].concat());
    let took = start.elapsed();
    assert!(!o.status.success(), "{args:?} was accepted");
    assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    assert!(!stderr(&o).contains("photon pass"), "{args:?} started rendering: {}", stderr(&o));
    // The render would take minutes; the check takes milliseconds (the
    // bound leaves room for a loaded machine).
    assert!(took < Duration::from_secs(10), "{args:?}: refused after {took:?}");
}

#[test]
fn an_output_that_is_also_an_input_is_refused_and_the_input_kept() {
    let dir = scratch_dir("outputs-inputs");
    // A scene file named like an image, with a mesh named like one too.
    let scene = dir.join("scene.exr");
    let mesh = dir.join("mesh.ppm");
    std::fs::write(&mesh, "v 9 -1 -4\nv 10 1 -4\nv 9 0 -3\nf 1 2 3\n").unwrap();
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tncg15.toml")).unwrap();
    let text = format!("{text}\n[[shapes]]\ntype = \"mesh\"\nfile = \"mesh.ppm\"\nmaterial = \"grey\"\n");
    std::fs::write(&scene, &text).unwrap();
    let reference = dir.join("ref.exr");
    let o = photonmap(&[TINY, &[s(&reference)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let reference_bytes = std::fs::read(&reference).unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--scene", s(&scene), s(&scene)], "the output is also the scene file"),
        (vec!["--scene", s(&scene), s(&mesh)], "the output is also the mesh"),
        (vec!["--reference", s(&reference), s(&reference)], "the output is also the --reference"),
        (vec!["--scene", s(&scene), "-o", s(&reference), "--reference", s(&reference), "x.exr"], "--reference"),
    ];
    for (args, message) in cases {
        refused_at_once(&args, message);
    }
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    assert_eq!(std::fs::read(&reference).unwrap(), reference_bytes);
    assert!(std::fs::read_to_string(&mesh).unwrap().starts_with("v 9"));
    assert_eq!(files_in(&dir), ["mesh.ppm", "ref.exr", "scene.exr"]);
}

#[test]
fn an_output_that_cannot_be_written_is_refused_before_rendering() {
    let dir = scratch_dir("outputs-unwritable");
    let file = dir.join("file.txt");
    std::fs::write(&file, "not a directory").unwrap();
    let a_directory = dir.join("dir.exr");
    std::fs::create_dir(&a_directory).unwrap();
    let good = dir.join("good.png");
    let in_file = file.join("x.exr");
    let missing = dir.join("missing/x.exr");
    let jpg = dir.join("x.jpg");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![s(&missing)], "does not exist"),
        (vec![s(&in_file)], "is not a directory"),
        (vec![s(&a_directory)], "is a directory"),
        (vec!["/proc/photonmap-test.exr"], "cannot create a file in /proc"),
        (vec![s(&jpg)], "unknown output extension"),
        // A good output beside a bad one: neither is written.
        (vec![s(&good), "-o", s(&missing)], "does not exist"),
        (vec![s(&good), "-o", s(&good)], "named twice as an output"),
        (vec!["--error-map", s(&missing), "--passes", "4", s(&good)], "does not exist"),
    ];
    for (args, message) in cases {
        refused_at_once(&args, message);
    }
    // A directory the user may not write in (root may write anywhere, so
    // this case is checked only where the permission holds).
    let locked = dir.join("locked");
    std::fs::create_dir(&locked).unwrap();
    set_mode(&locked, 0o555);
    match std::fs::write(locked.join("probe"), b"") {
        Err(_) => refused_at_once(&[s(&locked.join("x.exr"))], "cannot create a file in"),
        Ok(()) => std::fs::remove_file(locked.join("probe")).unwrap(),
    }
    set_mode(&locked, 0o755);
    assert_eq!(files_in(&dir), ["dir.exr", "file.txt", "locked"]);
    assert_eq!(files_in(&locked), Vec::<String>::new());
}

#[cfg(unix)]
fn set_mode(path: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap();
}

#[cfg(not(unix))]
fn set_mode(_: &Path, _: u32) {}

#[test]
fn a_read_only_file_is_not_replaced() {
    let dir = scratch_dir("outputs-read-only");
    let kept = dir.join("kept.exr");
    std::fs::write(&kept, b"an image the user protected").unwrap();
    let mut permissions = std::fs::metadata(&kept).unwrap().permissions();
    permissions.set_readonly(true);
    std::fs::set_permissions(&kept, permissions).unwrap();
    refused_at_once(&[s(&kept)], "read-only; it is not replaced");
    assert_eq!(std::fs::read(&kept).unwrap(), b"an image the user protected");
    assert!(std::fs::metadata(&kept).unwrap().permissions().readonly());
    assert_eq!(files_in(&dir), ["kept.exr"]);
}

/// Ctrl-C in a progressive render writes every output with the passes
/// done, exits 130 and leaves no temporary file.
#[cfg(unix)]
#[test]
fn ctrl_c_in_a_progressive_render_keeps_the_passes() {
    let dir = scratch_dir("outputs-ctrl-c");
    let (exr, png) = (dir.join("progressive.exr"), dir.join("progressive.png"));
    let child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(["--width", "48", "--height", "48", "--photons", "3e3", "--time", "600", s(&exr), "-o", s(&png)])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until some passes are done (the first write of the outputs).
    let start = Instant::now();
    while !exr.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(300));
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(130), "{}", stderr(&output));
    let header = read_header(&exr).unwrap();
    let passes = header.attributes.iter().find(|(k, _)| k == "passes").map(|(_, v)| v.clone()).unwrap();
    let done: u32 = passes.trim_start_matches("0..").parse().unwrap();
    assert!(done >= 1, "passes {passes}");
    assert!(stderr(&output).contains(&format!("{done} pass")), "{}", stderr(&output));
    assert_eq!(image::open(&png).unwrap().to_rgb8().dimensions(), (48, 48));
    assert_eq!(files_in(&dir), ["progressive.exr", "progressive.png"]);
}

#[test]
fn ppm_is_binary_p6() {
    let dir = scratch_dir("outputs-ppm");
    let ppm = dir.join("a.ppm");
    let o = photonmap(&[TINY, &[s(&ppm)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&ppm).unwrap();
    let header = b"P6\n16 16\n255\n";
    assert_eq!(&bytes[..header.len()], header);
    assert_eq!(bytes.len(), header.len() + 16 * 16 * 3);
}

#[test]
fn the_exr_says_how_it_was_made() {
    let dir = scratch_dir("outputs-provenance");
    let exr = dir.join("a.exr");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tncg15.toml");
    let o = photonmap(&[TINY, &["--scene", s(&scene), "--seed", "7", "--passes", "3", "--spp", "2", s(&exr)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let attributes = read_header(&exr).unwrap().attributes;
    let get = |key: &str| attributes.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str()).unwrap_or("(none)");
    assert_eq!(get("software"), format!("photonmap {}", env!("CARGO_PKG_VERSION")));
    assert!(get("scene").ends_with("tncg15.toml"), "{}", get("scene"));
    let text = std::fs::read(&scene).unwrap();
    assert_eq!(get("scene_sha256"), sha256_hex(&text));
    assert_eq!(get("integrator"), "photon");
    assert_eq!(get("seed"), "7");
    assert_eq!(get("passes"), "0..3");
    assert_eq!(get("spp"), "2");
    assert_eq!(get("photons_per_pass"), "1000 global, 1000 caustic");
    assert_eq!(get("photons_emitted"), "6000");
    let seconds: f64 = get("wall_seconds").parse().unwrap();
    assert!(seconds > 0.0 && seconds < 600.0);
    // `photonmap info` prints them.
    let o = photonmap(&["info", s(&exr)]);
    assert!(o.status.success());
    let info = String::from_utf8_lossy(&o.stdout);
    for (key, value) in [("seed", "7"), ("integrator", "photon"), ("passes", "0..3"), ("spp", "2")] {
        assert!(info.lines().any(|l| l.split_whitespace().collect::<Vec<_>>() == [key, value]), "{key}: {info}");
    }
}

/// The hash a user checks the scene file with (`sha256sum`).
fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn other_sizes_keep_the_pictures_aspect() {
    let dir = scratch_dir("outputs-aspect");
    // The course's corner camera has a square plane: 32 x 16 would stretch it.
    let o = photonmap(&[&["--width", "32", "--height", "16", "--quiet"], &[s(&dir.join("a.exr"))][..]].concat());
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("would stretch the picture") && stderr(&o).contains("give 32x32 or 16x16"),
        "{}",
        stderr(&o)
    );
    // A look-at camera widens its view: the spheres stay round.
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/02-cornell.toml");
    let wide = dir.join("wide.exr");
    let small = ["--photons", "1e3", "--caustic-photons", "1e3", "--quiet", "--width", "32", "--height", "16"];
    let o = photonmap(&[&small[..], &["--scene", s(&scene), s(&wide)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let film = photonmap::output::read_exr(&wide).unwrap();
    assert_eq!((film.width, film.height), (32, 16));
    assert_eq!(files_in(&dir), ["wide.exr"]);
}

/// The README's first command, with `-o out.png` added, gives a PNG a
/// person can see: the walls lit, not black apart from the lamp.
#[test]
fn the_readmes_first_command_gives_a_visible_png() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let command = readme.lines().find(|l| l.starts_with("cargo run")).expect("a command in README.md");
    let args: Vec<&str> = command.split_once(" -- ").expect("cargo run ... -- ARGS").1.split_whitespace().collect();
    let dir = scratch_dir("outputs-readme");
    let args: Vec<String> =
        args.iter().map(|a| if a.ends_with(".exr") { s(&dir.join(a)).to_string() } else { a.to_string() }).collect();
    let png = dir.join("out.png");
    let mut all: Vec<&str> = args.iter().map(String::as_str).collect();
    all.extend(["-o", s(&png), "--quiet"]);
    let o = photonmap(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    let image = image::open(&png).unwrap().to_rgb8();
    let values: Vec<f64> = image.pixels().flat_map(|p| p.0).map(f64::from).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    assert!((60.0..=190.0).contains(&mean), "mean 8-bit value {mean:.1}");
}
