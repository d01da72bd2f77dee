//! Rendering beyond one process: passes rendered as separate partial
//! renders (`--pass-range`, `--partial`) and added by `photonmap merge`
//! give the image one process gives, bit for bit, whatever the split and
//! the order; a render stopped by Ctrl-C resumes (`--resume`) to the image
//! an uninterrupted run gives; parts that do not belong together are
//! refused with the reason.

mod common;
use common::{photonmap, scratch_dir};
use photonmap::output::partial::read_partial;
use photonmap::output::read_exr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn ok(o: &Output) {
    assert!(o.status.success(), "exit {:?}: {}", o.status.code(), String::from_utf8_lossy(&o.stderr));
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A small progressive render: 32 x 32 pixels, 3000 photons per pass.
const SMALL: &[&str] = &["--width", "32", "--height", "32", "--photons", "3e3", "--quiet"];

/// The pixels of an EXR's R, G, B, as bits.
fn pixel_bits(path: &Path) -> Vec<u32> {
    let film = read_exr(path).unwrap();
    film.pixels.iter().flat_map(|c| c.to_array()).map(f32::to_bits).collect()
}

#[test]
fn merged_parts_equal_one_process_in_any_split_and_order() {
    let dir = scratch_dir("distributed-merge");
    let (one_exr, one_png) = (dir.join("one.exr"), dir.join("one.png"));
    ok(&photonmap(&[SMALL, &["--passes", "12", s(&one_exr), "-o", s(&one_png)]].concat()));
    let splits: [&[&str]; 3] = [&["0..1", "1..12"], &["0..4", "4..8", "8..12"], &["0..6", "6..12"]];
    for (k, split) in splits.iter().enumerate() {
        let parts: Vec<PathBuf> = split
            .iter()
            .map(|range| {
                let part = dir.join(format!("s{k}-{range}.exr"));
                ok(&photonmap(&[SMALL, &["--pass-range", range, "--partial", s(&part)]].concat()));
                part
            })
            .collect();
        // Merged last part first: addition order changes nothing.
        let (exr, png) = (dir.join(format!("m{k}.exr")), dir.join(format!("m{k}.png")));
        let mut args = vec!["merge", "--quiet", "-o", s(&exr), "-o", s(&png)];
        args.extend(parts.iter().rev().map(|p| s(p)));
        ok(&photonmap(&args));
        assert_eq!(pixel_bits(&exr), pixel_bits(&one_exr), "split {split:?}: EXR pixels differ");
        assert!(std::fs::read(&png).unwrap() == std::fs::read(&one_png).unwrap(), "split {split:?}: PNG bytes differ");
    }
}

#[test]
fn merge_refuses_parts_that_do_not_belong_together() {
    let dir = scratch_dir("distributed-refusals");
    let part = |name: &str, range: &str, extra: &[&str]| -> PathBuf {
        let p = dir.join(name);
        ok(&photonmap(&[SMALL, extra, &["--pass-range", range, "--partial", s(&p)]].concat()));
        p
    };
    let a = part("a.exr", "0..2", &[]);
    let b = part("b.exr", "2..4", &[]);
    let overlap = part("overlap.exr", "1..3", &[]);
    let later = part("later.exr", "5..6", &[]);
    let seed = part("seed.exr", "2..4", &["--seed", "9"]);
    let k = part("k.exr", "2..4", &["--k", "50"]);
    let out = dir.join("out.exr");
    let merge = |parts: &[&PathBuf], extra: &[&str]| -> Output {
        let mut args = vec!["merge", "--quiet", "-o", s(&out)];
        args.extend(extra);
        args.extend(parts.iter().map(|p| s(p)));
        photonmap(&args)
    };
    let refused = |o: Output, words: &[&str]| {
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(1), "{err}");
        for w in words {
            assert!(err.contains(w), "{w:?} not in: {err}");
        }
        assert!(!out.exists(), "a refused merge wrote its output");
    };
    refused(merge(&[&a, &overlap], &[]), &["overlap.exr", "a.exr", "both hold passes 1..2"]);
    refused(merge(&[&a, &later], &[]), &["passes 2..5 are missing", "--allow-gaps"]);
    // The field that differs is named, not left to be found in two long lines.
    refused(merge(&[&a, &seed], &[]), &["seed.exr", "settings differ: seed 1 against 9"]);
    refused(merge(&[&a, &k], &[]), &["k.exr", "settings differ: k_global 100 against 50"]);
    // Another image size.
    let big = dir.join("big.exr");
    ok(&photonmap(&[
        "--width",
        "40",
        "--height",
        "40",
        "--photons",
        "3e3",
        "--quiet",
        "--pass-range",
        "2..4",
        "--partial",
        s(&big),
    ]));
    refused(merge(&[&a, &big], &[]), &["big.exr", "image sizes differ", "32x32", "40x40"]);
    // Another scene: a scene file.
    let scene_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let scene = scene_dir.join("tncg15.toml");
    let other = dir.join("other.exr");
    ok(&photonmap(&[SMALL, &["--scene", s(&scene), "--pass-range", "2..4", "--partial", s(&other)]].concat()));
    refused(merge(&[&a, &other], &[]), &["other.exr", "scenes differ"]);
    // A gap is merged when asked for.
    ok(&merge(&[&later, &a], &["--allow-gaps"]));
    let merged = read_partial(&out).ok();
    assert!(merged.is_none(), "-o writes an image, not a partial");
    assert!(read_exr(&out).is_ok());
    // The good pair merges, and the merged partial says what it holds.
    let both = dir.join("both.exr");
    ok(&merge(&[&b, &a], &["--partial", s(&both)]));
    let p = read_partial(&both).unwrap();
    assert_eq!(p.manifest.passes, "0..4");
    assert_eq!(p.manifest.parts.len(), 2);
    assert_eq!(p.manifest.parts[0].passes, "0..2");
}

/// Ctrl-C keeps the passes done (in the partial, and an image); --resume
/// goes on from them to the image an uninterrupted run makes.
#[cfg(unix)]
#[test]
fn an_interrupted_render_resumes_to_the_uninterrupted_image() {
    let dir = scratch_dir("distributed-resume");
    let (part, image) = (dir.join("part.exr"), dir.join("image.exr"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args([SMALL, &["--passes", "100000", "--partial", s(&part), s(&image)]].concat())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let killed = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(killed.success());
    let start = Instant::now();
    let status = child.wait().unwrap();
    assert!(start.elapsed() < Duration::from_secs(20), "a stopped render took long to end");
    assert_eq!(status.code(), Some(130));
    let done = read_partial(&part).expect("the interrupted render's partial");
    let k = done.accumulation.passes.end();
    assert!(k >= 1 && done.accumulation.passes.is_prefix(), "passes {}", done.manifest.passes);
    assert!(read_exr(&image).is_ok(), "the interrupted render's image");
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 2, "files left: {leftovers:?}");

    let target = (k + 3).to_string();
    let resumed = dir.join("resumed.exr");
    ok(&photonmap(&[SMALL, &["--passes", &target, "--resume", s(&part), "--partial", s(&part), s(&resumed)]].concat()));
    let straight = dir.join("straight.exr");
    ok(&photonmap(&[SMALL, &["--passes", &target, s(&straight)]].concat()));
    assert_eq!(pixel_bits(&resumed), pixel_bits(&straight));
    let extended = read_partial(&part).unwrap();
    assert_eq!(extended.manifest.passes, format!("0..{target}"));
    assert_eq!(extended.manifest.parts.len(), 2);
}

#[test]
fn resume_refuses_other_settings() {
    let dir = scratch_dir("distributed-resume-refusal");
    let part = dir.join("part.exr");
    ok(&photonmap(&[SMALL, &["--passes", "2", "--partial", s(&part)]].concat()));
    let before = std::fs::read(&part).unwrap();
    let out = dir.join("out.exr");
    let o = photonmap(
        &[SMALL, &["--passes", "4", "--seed", "3", "--resume", s(&part), "--partial", s(&part), s(&out)]].concat(),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("part.exr") && err.contains("settings differ"), "{err}");
    assert!(std::fs::read(&part).unwrap() == before, "the partial was changed");
    assert!(!out.exists());
}
