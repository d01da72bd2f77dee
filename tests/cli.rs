//! The `photonmap` command: what a user types, what they get back.

mod common;
use common::{photonmap, scratch_dir};

use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const TINY: &[&str] = &["--width", "24", "--height", "24", "--spp", "1", "--quiet"];

#[test]
fn renders_exr_png_and_ppm_in_one_run() {
    let dir = scratch_dir("cli-outputs");
    let (exr, png, ppm) = (dir.join("a.exr"), dir.join("a.png"), dir.join("a.ppm"));
    let mut args = vec!["--photons", "2.5e3", "--caustic-photons", "1000", exr.to_str().unwrap()];
    args.extend(["-o", png.to_str().unwrap(), "--output", ppm.to_str().unwrap()]);
    args.extend(TINY);
    let o = photonmap(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let film = photonmap::output::read_exr(&exr).unwrap();
    assert_eq!((film.width, film.height), (24, 24));
    assert!(film.mean() > 0.0 && film.pixels.iter().all(|c| c.is_finite()));
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (24, 24));
    // Linear tone mapping: the brightest channel maps to 255.
    assert_eq!(img.pixels().flat_map(|p| p.0).max(), Some(255));
    assert_eq!(image::open(&ppm).unwrap().to_rgb8(), img);
    // No temporary files are left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
}

/// The same seed gives the same image on any number of threads: the same
/// pixels, bit for bit (tests/determinism.rs checks the film), the same
/// header but for the wall time, and the same PNG bytes.
#[test]
fn the_same_seed_writes_the_same_files_on_1_and_3_threads() {
    use photonmap::output::read_header;
    let dir = scratch_dir("cli-bytes");
    /// Pixel bits, header attributes, PNG bytes.
    type Run = (Vec<u32>, Vec<(String, String)>, Vec<u8>);
    let runs: Vec<Run> = ["1", "3"]
        .iter()
        .map(|threads| {
            let (exr, png) = (dir.join(format!("t{threads}.exr")), dir.join(format!("t{threads}.png")));
            let args = ["--photons", "2e4", "--width", "136", "--height", "136", "--spp", "1", "--quiet"];
            let o = photonmap(
                &[&args[..], &["--threads", threads, exr.to_str().unwrap(), "-o", png.to_str().unwrap()]].concat(),
            );
            assert!(o.status.success(), "{}", stderr(&o));
            let film = photonmap::output::read_exr(&exr).unwrap();
            let bits = film.pixels.iter().flat_map(|c| c.to_array()).map(f32::to_bits).collect();
            let mut attributes = read_header(&exr).unwrap().attributes;
            attributes.retain(|(k, _)| k != "wall_seconds");
            (bits, attributes, std::fs::read(&png).unwrap())
        })
        .collect();
    assert!(runs[0].0 == runs[1].0, "EXR pixels differ between 1 and 3 threads");
    assert_eq!(runs[0].1, runs[1].1);
    assert!(runs[0].2 == runs[1].2, "PNG files differ between 1 and 3 threads");
}

/// The count a render uses, as its EXR header says it, is the one written
/// in either notation (the caustic count following the global one).
#[test]
fn photon_counts_accept_plain_and_e_notation() {
    let dir = scratch_dir("cli-counts");
    for (given, used) in [("30000", 30_000), ("3e4", 30_000), ("2.5e4", 25_000), ("1200", 1200), ("0", 0)] {
        let exr = dir.join(format!("{used}-{}.exr", given.len()));
        let o = photonmap(&[&["--photons", given, exr.to_str().unwrap()], TINY].concat());
        assert!(o.status.success(), "{given}: {}", stderr(&o));
        let header = photonmap::output::read_header(&exr).unwrap();
        let said = header.attributes.iter().find(|(k, _)| k == "photons_per_pass").map(|(_, v)| v.as_str());
        assert_eq!(said, Some(format!("{used} global, {used} caustic").as_str()), "--photons {given}");
    }
}

#[test]
fn bad_flags_fail_with_a_message_and_leave_the_output_alone() {
    let dir = scratch_dir("cli-bad");
    let out = dir.join("keep.exr");
    std::fs::write(&out, b"precious").unwrap();
    let o = out.to_str().unwrap();
    let jpg = dir.join("out.jpg");
    let missing = dir.join("missing/out.exr");
    let cases: &[(&[&str], &str)] = &[
        (&["--photons", "abc", o], "not a number"),
        (&["--photons", "-5", o], "positive"),
        (&["--photons", "1e99", o], "1e9"),
        (&["--photons", "1.5", o], "whole number"),
        (&["--spp", "0", o], "spp"),
        (&["--eye", "3", o], "eye"),
        (&["--width", "0", o], "width"),
        (&["--max-radius", "-1", o], "positive distance"),
        (&["--photons", "1e9", o], "memory is available"),
        (&["--time", "1e30", o], "more than a week"),
        (&["--time", "0", o], "positive"),
        (&["--seed", "-1", o], "'-1' must be a whole number from 0 to 18446744073709551615"),
        (&["--seed", "1e30", o], "must be a whole number from 0"),
        (&["--width", "65536", "--height", "65536", o], "memory is available"),
        (&[jpg.to_str().unwrap()], "unknown output extension"),
        (&[missing.to_str().unwrap()], "does not exist"),
        (&[], "no output file"),
    ];
    for (args, message) in cases {
        let o = photonmap(args);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
    assert_eq!(std::fs::read(&out).unwrap(), b"precious");
}

/// The summary says how long the scene took to load and which files were
/// written, in lines that fit 100 columns; `trace`'s too.
#[test]
fn the_summary_names_loading_and_the_files_written_within_100_columns() {
    let dir = scratch_dir("cli-summary");
    let (exr, png) = (dir.join("summary.exr"), dir.join("summary.png"));
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/02-cornell.toml");
    for extra in [&["--passes", "4", "--window", "caustic=0:8,0:8"][..], &[][..]] {
        let mut args = vec!["--scene", scene.to_str().unwrap(), "--width", "32", "--height", "32"];
        args.extend(["--photons", "2e3", exr.to_str().unwrap(), "-o", png.to_str().unwrap()]);
        args.extend(extra);
        let o = photonmap(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = stderr(&o);
        let summary: Vec<&str> = text.split(['\n', '\r']).filter(|l| !l.is_empty()).collect();
        for line in &summary {
            assert!(line.chars().count() <= 100, "{} columns: {line}", line.chars().count());
        }
        assert!(summary.iter().any(|l| l.trim_start().starts_with("scene load")), "{text}");
        for file in [&exr, &png] {
            assert!(summary.iter().any(|l| l.contains(file.to_str().unwrap())), "{} not named: {text}", file.display());
        }
    }
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/whitted-spheres.toml");
    let out = dir.join("trace.png");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_trace"))
        .args([scene.to_str().unwrap(), out.to_str().unwrap(), "--width", "32", "--height", "32"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stderr(&o);
    assert!(text.lines().all(|l| l.chars().count() <= 100), "{text}");
    assert!(text.contains("scene load") && text.contains(out.to_str().unwrap()), "{text}");
}

#[test]
fn a_scene_without_lights_is_refused_with_that_reason() {
    let dir = scratch_dir("cli-no-light");
    let text =
        std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tncg15.toml")).unwrap();
    let scene = dir.join("dark.toml");
    std::fs::write(&scene, &text[..text.find("[[lights]]").unwrap()]).unwrap();
    let out = dir.join("dark.exr");
    let o = photonmap(&["--scene", scene.to_str().unwrap(), out.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("dark.toml: the scene has no light"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn zero_photons_renders_direct_light_and_warns() {
    let dir = scratch_dir("cli-zero");
    let out = dir.join("direct.exr");
    let o = photonmap(&[
        "--photons",
        "0",
        "--caustic-photons",
        "0",
        "--width",
        "16",
        "--height",
        "16",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("indirect light is missing"));
    assert!(stderr(&o).contains("caustics are missing"));
    let film = photonmap::output::read_exr(&out).unwrap();
    assert!(film.mean() > 0.0);
}

#[test]
fn progressive_and_path_tracing_runs_write_their_output() {
    let dir = scratch_dir("cli-progressive");
    for (name, extra) in [
        ("passes.exr", &["--passes", "3", "--photons", "2e3"][..]),
        ("time.exr", &["--time", "0.5", "--photons", "2e3"][..]),
        ("path.exr", &["--integrator", "path", "--passes", "2"][..]),
    ] {
        let out = dir.join(name);
        let mut args = vec![out.to_str().unwrap()];
        args.extend(extra);
        args.extend(TINY);
        let o = photonmap(&args);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let film = photonmap::output::read_exr(&out).unwrap();
        assert!(film.mean() > 0.0 && film.pixels.iter().all(|c| c.is_finite()), "{name}");
    }
    let o = photonmap(&["--pass-range", "0..2", "--resume", "p.exr", "--partial", "p.exr"]);
    assert!(!o.status.success() && stderr(&o).contains("cannot be used with"));
    let o = photonmap(&["--alpha", "1.5", dir.join("x.exr").to_str().unwrap()]);
    assert!(!o.status.success() && stderr(&o).contains("between 0 and 1"));
}

/// `export --origin` takes negative coordinates as a value (the suite's
/// Cornell box places Mitsuba's origin at x = -0.4), and the written eye
/// is the scene's eye less the origin, times the scale.
#[test]
fn export_takes_a_negative_origin() {
    let dir = scratch_dir("cli-export-origin");
    let xml = dir.join("cornell.xml");
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/02-cornell.toml");
    let o = photonmap(&[
        "export",
        "--mitsuba",
        scene.to_str().unwrap(),
        xml.to_str().unwrap(),
        "--origin",
        "-0.4,0.05,0.35",
        "--scale",
        "100",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&xml).unwrap();
    // The eye (0, -3.4, 1) less (-0.4, 0.05, 0.35), times 100.
    assert!(text.contains("lookat origin=\"40, -345, 65\""), "{text}");
}

/// A progressive render given no photon counts takes four times the
/// caustic photons at four times the caustic k (the estimates' disks of
/// 250,000 photons at k = 100), or in a scene with media four times the
/// global photons; given a count, or a k, it keeps what it was given (the
/// caustic count following the global one).
#[test]
fn progressive_passes_take_more_caustic_photons_where_given_no_counts() {
    const FOG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/suite/12-fog-shafts.toml");
    let dir = scratch_dir("cli-progressive-counts");
    let cases: &[(&[&str], &str, &str)] = &[
        (&[], "250000 global, 1000000 caustic", "k_caustic: 400,"),
        (&["--photons", "2e4"], "20000 global, 20000 caustic", "k_caustic: 100,"),
        (&["--caustic-photons", "3e4"], "250000 global, 30000 caustic", "k_caustic: 100,"),
        (&["--k-caustic", "50"], "250000 global, 1000000 caustic", "k_caustic: 50,"),
        // A caustic photon in a medium goes on through it: not the cheap part
        // there; the global photons, read through the volume grid, are.
        (&["--scene", FOG, "--integrator", "photon"], "1000000 global, 250000 caustic", "k_caustic: 100,"),
        (
            &["--scene", FOG, "--integrator", "photon", "--k-caustic", "50"],
            "1000000 global, 250000 caustic",
            "k_caustic: 50,",
        ),
        (
            &["--scene", FOG, "--integrator", "photon", "--photons", "2e4"],
            "20000 global, 20000 caustic",
            "k_caustic: 100,",
        ),
    ];
    for (i, (given, photons, k)) in cases.iter().enumerate() {
        let exr = dir.join(format!("p{i}.exr"));
        let args = ["--passes", "1", "--width", "8", "--height", "8", "--quiet", exr.to_str().unwrap()];
        let o = photonmap(&[&args[..], given].concat());
        assert!(o.status.success(), "{given:?}: {}", stderr(&o));
        let header = photonmap::output::read_header(&exr).unwrap();
        let get = |key: &str| header.attributes.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
        assert_eq!(get("photons_per_pass").as_deref(), Some(*photons), "{given:?}");
        assert!(get("settings").unwrap().contains(k), "{given:?}: {:?}", get("settings"));
    }
}

/// In a scene with participating media the photon camera pass neither aims
/// gather rays nor reuses caustic estimates: a value set for either is
/// warned of by name, not silently ignored; left at its default, nothing
/// is said.
#[test]
fn flags_that_media_do_not_use_are_named() {
    const FOG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/suite/12-fog-shafts.toml");
    let dir = scratch_dir("cli-media-flags");
    let exr = dir.join("fog.exr");
    let base = ["--scene", FOG, "--integrator", "photon", "--photons", "1e3", "--caustic-photons", "1e3"];
    let small = ["--width", "8", "--height", "8", "--spp", "1", exr.to_str().unwrap()];
    for (given, warned) in [
        (&[][..], &[][..]),
        (&["--aimed-gather-rays", "2"][..], &["--aimed-gather-rays"][..]),
        (&["--caustic-reuse", "0.3"][..], &["--caustic-reuse"][..]),
    ] {
        let o = photonmap(&[&base[..], given, &small[..]].concat());
        assert!(o.status.success(), "{given:?}: {}", stderr(&o));
        let said = stderr(&o);
        for flag in ["--aimed-gather-rays", "--caustic-reuse"] {
            let line = format!("warning: {flag} has no effect in a scene with participating media");
            assert_eq!(said.contains(&line), warned.contains(&flag), "{given:?}: {said}");
        }
    }
}
