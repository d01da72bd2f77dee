//! What a hostile newcomer tries: a scene of many entries, a scene "file"
//! that is a device, a FIFO or a directory, signals while loading, outputs
//! of the wrong kind, runs without an end, lights a path tracer cannot see,
//! a reference of another view. Each is refused before any rendering, said,
//! or honoured; none runs forever or answers wrongly with exit code 0.

mod common;
use common::{photonmap, scratch_dir};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Settings whose render takes minutes: a refusal that comes back at once
/// was made before rendering.
const HEAVY: &[&str] = &["--photons", "3e7", "--caustic-photons", "3e7", "--width", "2000", "--height", "2000"];

const TINY: &[&str] = &["--width", "16", "--height", "16", "--photons", "1e3", "--caustic-photons", "1e3"];

/// Runs `program` with `args`, killing it if it has not ended by
/// `deadline` (a run that never ends fails the test instead of hanging it).
fn run_within(program: &str, args: &[&str], deadline: Duration) -> Output {
    let mut child = Command::new(program).args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > deadline {
            let _ = child.kill();
            let o = child.wait_with_output().unwrap();
            panic!("{program} {args:?} still ran after {deadline:?}: {}", stderr(&o));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// A child's standard error, line by line as it comes.
fn stderr_lines(child: &mut Child) -> Receiver<String> {
    let (send, lines) = channel();
    let pipe = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    lines
}

/// Waits for a line containing `text`; returns the lines read so far.
fn wait_for(lines: &Receiver<String>, text: &str, deadline: Duration, child: &mut Child) -> Vec<String> {
    let start = Instant::now();
    let mut seen = Vec::new();
    while start.elapsed() < deadline {
        if let Ok(line) = lines.recv_timeout(Duration::from_millis(100)) {
            let found = line.contains(text);
            seen.push(line);
            if found {
                return seen;
            }
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    panic!("no line with {text:?} within {deadline:?}: {seen:?}");
}

fn signal(child: &Child, name: &str) {
    let pid = child.id().to_string();
    assert!(Command::new("kill").args([&format!("-{name}"), pid.as_str()]).status().unwrap().success());
}

/// The default room with `n` small spheres appended (the load of issue 44:
/// quadratic in the entries, 100,000 took about 12 minutes).
fn many_spheres(dir: &Path, n: usize) -> PathBuf {
    use std::fmt::Write;
    let mut text = std::fs::read_to_string(root().join("scenes/tncg15.toml")).unwrap();
    for i in 0..n {
        let (a, b, c) = (i % 50, (i / 50) % 50, (i / 2500) % 48);
        let (x, y, z) = (1.5 + 0.18 * a as f32, -4.5 + 0.18 * b as f32, -3.5 + 0.15 * c as f32);
        write!(text, "\n[[shapes]]\ntype = \"sphere\"\ncenter = [{x}, {y}, {z}]\nradius = 0.02\nmaterial = \"grey\"\n")
            .unwrap();
    }
    let path = dir.join(format!("spheres-{n}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// A load of over a second says so; a signal then (SIGINT or SIGTERM)
/// ends the run at once, with nothing written: there is nothing to keep.
#[cfg(unix)]
#[test]
fn a_long_load_says_so_and_a_signal_ends_it_at_once() {
    let dir = scratch_dir("hostile-long-load");
    // About three seconds to load on a 2-core machine (linear: ~10 µs an
    // entry); before the fix, hours.
    let scene = many_spheres(&dir, 300_000);
    let out = dir.join("out.exr");
    for name in ["INT", "TERM"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
            .args(["--scene", s(&scene), "--photons", "1e3", "--width", "16", "--height", "16", s(&out)])
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let lines = stderr_lines(&mut child);
        wait_for(&lines, "loading", Duration::from_secs(60), &mut child);
        let sent = Instant::now();
        signal(&child, name);
        let status = child.wait().unwrap();
        let rest: Vec<String> = lines.try_iter().collect();
        assert_eq!(status.code(), Some(130), "SIG{name}: {rest:?}");
        assert!(sent.elapsed() < Duration::from_secs(2), "SIG{name}: ended {:?} after the signal", sent.elapsed());
        assert!(rest.iter().any(|l| l.contains("interrupted")), "SIG{name}: {rest:?}");
        assert!(!rest.iter().any(|l| l.contains("scene load")), "SIG{name}: the load finished first: {rest:?}");
        assert!(!out.exists());
    }
}

/// A scene "file" that is not a regular file, or is larger than a scene
/// file may be, is refused at once with what it is, by both programs.
#[cfg(unix)]
#[test]
fn a_scene_file_that_is_not_a_regular_file_is_refused_at_once() {
    let dir = scratch_dir("hostile-not-a-file");
    let fifo = dir.join("scene.fifo");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let huge = dir.join("huge.toml");
    // Sparse: no disk space is used.
    std::fs::File::create(&huge).unwrap().set_len(photonmap::scene::file::MAX_SCENE_BYTES + 1).unwrap();
    let out = dir.join("out.png");
    let cases: &[(&Path, &str)] = &[
        (Path::new("/dev/zero"), "it is a device, not a regular file"),
        (&fifo, "it is a FIFO (named pipe), not a regular file"),
        (&dir, "it is a directory"),
        (&huge, "more than the 100 MB a scene file may be"),
    ];
    for (scene, message) in cases {
        for (program, args) in [
            (env!("CARGO_BIN_EXE_trace"), vec![s(scene), s(&out)]),
            (env!("CARGO_BIN_EXE_photonmap"), vec!["--scene", s(scene), s(&out)]),
        ] {
            // Before: /dev/zero was read until the kernel killed the
            // process (24 GB), the FIFO blocked forever.
            let o = run_within(program, &args, Duration::from_secs(20));
            assert_eq!(o.status.code(), Some(1), "{program} {}: {}", scene.display(), stderr(&o));
            assert!(stderr(&o).contains(message), "{program} {}: {}", scene.display(), stderr(&o));
            assert!(!out.exists());
        }
    }
}

/// SIGTERM is honoured as Ctrl-C is: a progressive render keeps its
/// passes and exits 130.
#[cfg(unix)]
#[test]
fn sigterm_in_a_progressive_render_keeps_the_passes() {
    let dir = scratch_dir("hostile-sigterm");
    let exr = dir.join("progressive.exr");
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(["--width", "32", "--height", "32", "--photons", "3e3", "--time", "600", s(&exr)])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = stderr_lines(&mut child);
    wait_for(&lines, "pass ", Duration::from_secs(60), &mut child);
    signal(&child, "TERM");
    let status = child.wait().unwrap();
    let rest: Vec<String> = lines.try_iter().collect();
    assert_eq!(status.code(), Some(130), "{status:?} {rest:?}");
    assert!(rest.iter().any(|l| l.contains("interrupted; the passes finished are written")), "{rest:?}");
    let header = photonmap::output::read_header(&exr).unwrap();
    assert!(header.get("passes").is_some_and(|p| p.starts_with("0..")), "{:?}", header.attributes);
}

/// A partial render is an EXR of exact sums and an error map an 8-bit
/// picture: the wrong kind is refused before rendering, not after the
/// passes it was to hold (before: exit 1 after the whole --pass-range, the
/// error printed twice; with --time, at the first checkpoint).
#[test]
fn a_partial_or_error_map_of_the_wrong_kind_is_refused_before_rendering() {
    let dir = scratch_dir("hostile-partial-kind");
    let (out, png, exr) = (dir.join("out.exr"), dir.join("part.png"), dir.join("error.exr"));
    let cases: &[(&[&str], &str)] = &[
        (&["--pass-range", "0..2", "--partial", s(&png)], "a partial render is an .exr file"),
        (&["--time", "600", "--partial", s(&png)], "a partial render is an .exr file"),
        (&["--passes", "4", "--error-map", s(&exr)], "the error map is an 8-bit picture"),
    ];
    for (args, message) in cases {
        let start = Instant::now();
        let o =
            run_within(env!("CARGO_BIN_EXE_photonmap"), &[HEAVY, args, &[s(&out)]].concat(), Duration::from_secs(60));
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).matches("photonmap: error").count(), 1, "{args:?}: {}", stderr(&o));
        assert!(start.elapsed() < Duration::from_secs(10), "{args:?}: refused after {:?}", start.elapsed());
        assert!(!out.exists() && !png.exists() && !exr.exists());
    }
}

/// --resume with nothing to end it is refused (before: it ran until
/// signalled); a --target-error out of reach is said, with the week that
/// bounds it (before: it ran forever, its ETA 1.4e16 s).
#[cfg(unix)]
#[test]
fn runs_without_an_end_are_refused_or_bounded() {
    let dir = scratch_dir("hostile-no-end");
    let (part, out) = (dir.join("part.exr"), dir.join("out.exr"));
    let o = photonmap(&[TINY, &["--passes", "2", "--quiet", "--partial", s(&part), s(&out)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let resumed = dir.join("resumed.exr");
    let o = run_within(
        env!("CARGO_BIN_EXE_photonmap"),
        &[TINY, &["--resume", s(&part), s(&resumed)]].concat(),
        Duration::from_secs(30),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--resume needs --passes, --time or --target-error"), "{}", stderr(&o));
    assert!(!resumed.exists());

    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args([TINY, &["--target-error", "1e-9", s(&out)]].concat())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = stderr_lines(&mut child);
    let seen = wait_for(&lines, "warning: --target-error 1e-9", Duration::from_secs(60), &mut child);
    let warning = seen.last().unwrap();
    assert!(warning.contains("after a week (604800 s"), "{warning}");
    signal(&child, "INT");
    assert_eq!(child.wait().unwrap().code(), Some(130));
}

/// A scene of a glass sphere around a point light, with the light inside
/// or above it.
fn point_light_and_glass(dir: &Path, light_z: f32) -> PathBuf {
    let text = format!(
        r#"
        [camera]
        eye = [-2, 0, 0]
        target = [5, 0, -1]
        up = [0, 0, 1]
        vfov = 60
        width = 16
        height = 16
        [materials.white]
        type = "lambertian"
        rho = [0.7, 0.7, 0.7]
        [materials.glass]
        type = "glass"
        ior = 1.5
        [[shapes]]
        type = "room"
        floor = "white"
        ceiling = "white"
        walls = ["white", "white", "white", "white", "white", "white"]
        [[shapes]]
        type = "sphere"
        center = [6, 0, -2]
        radius = 1
        material = "glass"
        [[lights]]
        type = "point"
        position = [6, 0, {light_z}]
        color = [5, 5, 5]
        "#
    );
    let path = dir.join(format!("point-{light_z}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The path tracer cannot find a point light through glass: one only
/// reachable through it is refused with that reason (before: a black image,
/// exit 0, from "the unbiased reference"); one whose power partly meets
/// glass first renders, with a warning that its caustics are missing.
#[test]
fn the_path_tracer_refuses_a_point_light_it_cannot_see() {
    let dir = scratch_dir("hostile-path-glass");
    let out = dir.join("out.exr");
    let inside = point_light_and_glass(&dir, -2.0);
    let o = photonmap(&["--scene", s(&inside), "--integrator", "path", "--spp", "1", s(&out)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the point light at [6, 0, -2] reaches the scene only through mirrors or glass"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    // Photon mapping carries that light: the image is not black.
    let o = photonmap(&["--scene", s(&inside), "--photons", "2e4", "--spp", "1", "--quiet", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(photonmap::output::read_exr(&out).unwrap().mean() > 0.0);

    let above = point_light_and_glass(&dir, 2.0);
    let o = photonmap(&["--scene", s(&above), "--integrator", "path", "--spp", "1", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("of the power of the point light at [6, 0, 2] first meets mirrors or glass"));
}

/// A reference says what it shows (its provenance): one of another view is
/// refused; one that says nothing is warned of when the render is not the
/// default view (before: scored against the wrong view without a word).
#[test]
fn a_reference_of_another_view_is_refused_or_warned_of() {
    let dir = scratch_dir("hostile-reference");
    let (reference, out) = (dir.join("eye1.exr"), dir.join("out.exr"));
    let o = photonmap(&[TINY, &["--quiet", s(&reference)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = photonmap(&[TINY, &["--eye", "2", "--reference", s(&reference), s(&out)]].concat());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o)
        .contains("it is a render of built-in TNCG15 room, eye 1, this is a render of built-in TNCG15 room, eye 2"));
    assert!(!out.exists());
    // The same view is scored.
    let o = photonmap(&[TINY, &["--reference", s(&reference), s(&out)]].concat());
    assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", stderr(&o));
    // The Mitsuba reference carries no provenance.
    let mitsuba = root().join("tests/data/default_e1_200.exr");
    let size = ["--width", "200", "--height", "200", "--photons", "1e3", "--caustic-photons", "1e3", "--spp", "1"];
    let o = photonmap(&[&size[..], &["--eye", "2", "--reference", s(&mitsuba), s(&out)]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("does not say what it shows"), "{}", stderr(&o));
    let o = photonmap(&[&size[..], &["--reference", s(&mitsuba), s(&out)]].concat());
    assert!(!stderr(&o).contains("does not say what it shows"), "{}", stderr(&o));
}

/// `trace` refuses a scene without light as photonmap does (before: a
/// black image, exit 0).
#[test]
fn trace_refuses_a_scene_without_light() {
    let dir = scratch_dir("hostile-trace-dark");
    let scene = dir.join("dark.toml");
    let text = std::fs::read_to_string(point_light_and_glass(&dir, 2.0)).unwrap();
    std::fs::write(&scene, text.split("[[lights]]").next().unwrap()).unwrap();
    let out = dir.join("dark.png");
    let o = Command::new(env!("CARGO_BIN_EXE_trace")).args([s(&scene), s(&out)]).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("the scene has no light"), "{}", stderr(&o));
    assert!(!out.exists());
}
