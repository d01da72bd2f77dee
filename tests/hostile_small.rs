//! The smaller mistakes of issue 44: a checkpoint that cannot be written, a
//! signal during the final write, counts in e-notation, negative values in
//! subcommands, more threads than cores, a truncated partial, an export
//! over another scene's meshes, "1 passes".

mod common;
use common::{photonmap, scratch_dir};
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const TINY: &[&str] = &["--width", "16", "--height", "16", "--photons", "1e3", "--caustic-photons", "1e3"];

/// A checkpoint that cannot be written (its directory gone) is said, and
/// the render goes on to write at the end (before: exit 1 at the first
/// failed checkpoint, the passes lost).
#[cfg(unix)]
#[test]
fn a_checkpoint_that_cannot_be_written_does_not_stop_the_render() {
    let dir = scratch_dir("hostile-checkpoint");
    let (outs, away) = (dir.join("outs"), dir.join("away"));
    std::fs::create_dir(&outs).unwrap();
    let exr = outs.join("run.exr");
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(["--width", "32", "--height", "32", "--photons", "3e3", "--time", "16", s(&exr)])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines().map_while(Result::ok);
    // Rendering has begun (its outputs were checked): take the directory away.
    assert!(lines.by_ref().any(|l| l.starts_with("pass ")), "no pass line");
    std::fs::rename(&outs, &away).unwrap();
    // The first checkpoint (at 10 s) fails and is said; the directory comes back.
    let warning = lines.by_ref().find(|l| l.contains("warning")).expect("no warning of the failed checkpoint");
    assert!(warning.contains("the render goes on"), "{warning}");
    std::fs::rename(&away, &outs).unwrap();
    let rest: Vec<String> = lines.collect();
    let status = child.wait().unwrap();
    assert!(status.success(), "{rest:?}");
    assert!(rest.iter().any(|l| l.contains("--time is up")), "{rest:?}");
    let header = photonmap::output::read_header(&exr).unwrap();
    assert!(header.get("passes").is_some_and(|p| p.starts_with("0..")));
}

/// A signal while the outputs are written leaves them whole and ends the
/// run as interrupted (before: exit 0, as if it had run its course).
#[cfg(unix)]
#[test]
fn a_signal_during_the_final_write_is_not_success() {
    let dir = scratch_dir("hostile-final-write");
    let (exr, png, ppm) = (dir.join("a.exr"), dir.join("b.png"), dir.join("c.ppm"));
    // A large image of a cheap render: the writes take about a second.
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(["--width", "2000", "--height", "2000", "--photons", "1e2", "--caustic-photons", "1e2"])
        .args(["--spp", "1", "--gather-rays", "0", "--edge-spp", "0", "--shadow-rays", "1"])
        .args([s(&exr), "-o", s(&png), "-o", s(&ppm)])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The camera pass is done (the outputs' up-front check, which makes
    // and removes a probe file, is long past); the lines after it are kept.
    let (send, lines) = std::sync::mpsc::channel();
    let pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut rest = Vec::new();
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            if line.contains("camera pass: 100%") {
                let _ = send.send(());
            }
            rest.push(line);
        }
        rest
    });
    lines.recv_timeout(Duration::from_secs(120)).expect("the camera pass did not end");
    let start = Instant::now();
    let writing =
        || std::fs::read_dir(&dir).unwrap().any(|e| e.unwrap().file_name().to_string_lossy().ends_with(".tmp"));
    while !writing() {
        assert!(start.elapsed() < Duration::from_secs(120), "no output was written");
        std::thread::sleep(Duration::from_millis(2));
    }
    let pid = child.id().to_string();
    assert!(Command::new("kill").args(["-INT", pid.as_str()]).status().unwrap().success());
    let status = child.wait().unwrap();
    let rest = reader.join().unwrap().join("\n");
    assert_eq!(status.code(), Some(130), "{rest}");
    assert!(rest.contains("interrupted while writing; the outputs written are complete"), "{rest}");
    // What was written is whole (a temporary renamed into place), and no
    // temporary is left.
    assert_eq!(photonmap::output::read_exr(&exr).unwrap().width, 2000);
    assert!(!writing());
}

/// Every count takes the notation --photons takes (before: `--spp 1e3`
/// was "invalid digit found in string"), in both programs.
#[test]
fn every_count_takes_e_notation() {
    let dir = scratch_dir("hostile-counts");
    let out = dir.join("out.exr");
    let o = photonmap(&[
        "--width",
        "1.6e1",
        "--height",
        "16",
        "--photons",
        "1e3",
        "--spp",
        "2e0",
        "--passes",
        "2e0",
        "--k",
        "5e1",
        "--gather-rays",
        "2e0",
        "--threads",
        "1e0",
        "--quiet",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = photonmap(&["--spp", "1e9", s(&out)]);
    assert!(stderr(&o).contains("'1e9' is not from 1 to 1000000"), "{}", stderr(&o));
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/whitted-spheres.toml");
    let png = dir.join("out.png");
    let o = Command::new(env!("CARGO_BIN_EXE_trace"))
        .args([s(&scene), s(&png), "1e0", "--width", "3.2e1", "--height", "24", "--spp", "1e0", "-q"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A negative number in a subcommand is a value, refused for what it is
/// (before: "unexpected argument '-1' found").
#[test]
fn negative_numbers_in_subcommands_are_values() {
    let dir = scratch_dir("hostile-negative");
    let o = photonmap(&["export", "--mitsuba", s(&dir.join("room.xml")), "--scale", "-1"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("scale -1: give a positive number"), "{}", stderr(&o));
}

/// More threads than cores are said to only add overhead; one pass and one
/// thread are said in the singular (before: "1 threads").
#[test]
fn threads_beyond_the_cores_are_warned_of_and_counts_read_well() {
    let dir = scratch_dir("hostile-threads");
    let out = dir.join("out.exr");
    let cores = std::thread::available_parallelism().unwrap().get();
    let o = photonmap(&[TINY, &["--threads", &(cores + 1).to_string(), s(&out)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains(&format!("is more than the {cores} cores")), "{}", stderr(&o));
    let o = photonmap(&[TINY, &["--threads", "1", s(&out)]].concat());
    assert!(stderr(&o).contains("photonmap: photon mapping, 1 pass, 1 thread, 16 x 16"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("more than the"), "{}", stderr(&o));
}

/// `info` reads a partial's pixels, not only its header, and says when
/// the file is cut short (before: a full description, exit 0).
#[test]
fn info_says_when_a_partial_is_truncated() {
    let dir = scratch_dir("hostile-info");
    let (part, out, cut) = (dir.join("part.exr"), dir.join("out.exr"), dir.join("cut.exr"));
    let o = photonmap(&[TINY, &["--passes", "2", "--quiet", "--partial", s(&part), s(&out)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = photonmap(&["info", s(&part)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&part).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() * 3 / 4]).unwrap();
    let o = photonmap(&["info", s(&cut)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("the file is truncated or damaged"));
}

/// `export` does not create a missing directory (rendering refuses one)
/// and does not replace another scene's mesh files; the same scene exported
/// again is written (before: both were written over or created).
#[test]
fn export_neither_creates_directories_nor_replaces_other_meshes() {
    let dir = scratch_dir("hostile-export");
    let room = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tncg15.toml");
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/suite/02-cornell.toml");
    let missing = dir.join("missing/room.xml");
    let o = photonmap(&["export", "--mitsuba", s(&room), s(&missing)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("does not exist"), "{}", stderr(&o));
    assert!(!dir.join("missing").exists());
    let xml = dir.join("room.xml");
    for _ in 0..2 {
        let o = photonmap(&["export", "--mitsuba", s(&room), s(&xml)]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let mesh = dir.join("room-meshes/000.ply");
    let before = std::fs::read(&mesh).unwrap();
    let o = photonmap(&["export", "--mitsuba", s(&cornell), s(&xml)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("a mesh file is already there, with other contents"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&mesh).unwrap(), before);
}

/// `export` of a Mitsuba XML scene is refused by what it is (before: read
/// as TOML, it failed with "key with no value, expected `=`").
#[test]
fn export_refuses_a_mitsuba_scene_by_name() {
    let dir = scratch_dir("hostile-export-xml");
    let input = dir.join("scene.xml");
    std::fs::write(&input, "<scene version=\"3.0.0\"/>\n").unwrap();
    let o = photonmap(&["export", "--mitsuba", s(&input), s(&dir.join("out.xml"))]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("scene.xml: export writes photonmap's TOML scenes"), "{}", stderr(&o));
    assert!(!dir.join("out.xml").exists());
}
