//! `photonmap compare`: known differences give known numbers through the
//! command line, windows are scored, size rules hold, nothing is lost.

mod common;
use common::{photonmap, scratch_dir};
use photonmap::film::Film;
use photonmap::math::Color;
use photonmap::output::write;
use std::path::Path;
use std::process::Output;

fn exr(dir: &Path, name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> String {
    let film = Film { width: w, height: h, pixels: (0..w * h).map(|i| Color::splat(f(i % w, i / w))).collect() };
    let path = dir.join(name);
    write(&path, &film, Default::default(), 1.0).unwrap();
    path.to_str().unwrap().to_string()
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("compare --json prints JSON")
}

/// A test twice the reference's size whose 2x2 blocks average to the
/// reference plus 0.1, and plus 0.4 in a window: RMSE, bias and the
/// window's numbers are the known ones.
#[test]
fn a_known_difference_gives_the_known_numbers() {
    let dir = scratch_dir("compare-known");
    let reference = exr(&dir, "ref.exr", 20, 10, |_, _| 0.5);
    let test = exr(&dir, "test.exr", 40, 20, |x, y| {
        let spot = (6..10).contains(&(x / 2)) && (2..4).contains(&(y / 2));
        let base = if spot { 0.9 } else { 0.6 };
        // +-0.05 within each 2x2 block: averaged away by the reduction.
        base + if (x + y) % 2 == 0 { 0.05 } else { -0.05 }
    });
    let v = json(&photonmap(&["compare", &test, &reference, "--json", "--window", "spot=2:4,6:10"]));
    assert_eq!(v["factor"], 2);
    let whole = &v["whole"];
    let want = ((8.0 * 0.16 + 192.0 * 0.01) / 200.0f64).sqrt();
    assert!((whole["rmse"].as_f64().unwrap() - want).abs() < 1e-6, "{whole}");
    assert!((whole["mean_ref"].as_f64().unwrap() - 0.5).abs() < 1e-6);
    let spot = &v["windows"][0];
    assert_eq!(spot["name"], "spot");
    assert_eq!(spot["pixels"], 8);
    assert!((spot["rmse"].as_f64().unwrap() - 0.4).abs() < 1e-6, "{spot}");
    assert!((spot["bias"].as_f64().unwrap() - 0.8).abs() < 1e-6, "{spot}");
    assert!((spot["relmse"].as_f64().unwrap() - 0.16 / 0.26).abs() < 1e-6, "{spot}");
    assert_eq!(v["nan_count"], 0);
    // The table names the window too.
    let o = photonmap(&["compare", &test, &reference, "--window", "spot=2:4,6:10"]);
    assert!(o.status.success() && String::from_utf8_lossy(&o.stdout).contains("spot"));
}

#[test]
fn sizes_that_are_not_a_multiple_are_refused() {
    let dir = scratch_dir("compare-sizes");
    let reference = exr(&dir, "ref.exr", 20, 10, |_, _| 0.5);
    for (w, h) in [(30, 10), (40, 10), (10, 5), (21, 10)] {
        let test = exr(&dir, &format!("t{w}x{h}.exr"), w, h, |_, _| 0.5);
        let o = photonmap(&["compare", &test, &reference]);
        assert!(!o.status.success(), "{w}x{h} accepted");
        assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be compared"), "{w}x{h}");
    }
    let test = exr(&dir, "t.exr", 20, 10, |_, _| 0.5);
    let o = photonmap(&["compare", &test, &reference, "--window", "0:11,0:5"]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("outside"));
    let o = photonmap(&["compare", &test, &reference, "--window", "5:2,0:5"]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--window"));
}

/// The difference picture is written at the reference's size, red where
/// the test is brighter and blue where darker; it may not replace an input.
#[test]
fn the_difference_picture_is_signed_and_never_replaces_an_input() {
    let dir = scratch_dir("compare-diff");
    let reference = exr(&dir, "ref.exr", 8, 4, |_, _| 0.5);
    let test = exr(&dir, "test.exr", 16, 8, |x, _| if x < 8 { 0.7 } else { 0.3 });
    let png = dir.join("diff.png");
    let v = json(&photonmap(&["compare", &test, &reference, "--json", "--diff", png.to_str().unwrap()]));
    assert!((v["diff_scale"].as_f64().unwrap() - 0.2).abs() < 1e-5, "{v}");
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (8, 4));
    let (left, right) = (img.get_pixel(0, 0).0, img.get_pixel(7, 3).0);
    assert!(left[0] == 255 && left[2] < 255, "{left:?}");
    assert!(right[2] == 255 && right[0] < 255, "{right:?}");
    let before = std::fs::read(&reference).unwrap();
    let o = photonmap(&["compare", &test, &reference, "--diff", &reference]);
    assert!(!o.status.success());
    assert_eq!(std::fs::read(&reference).unwrap(), before);
}

/// `--reference` scores a render with the same code: its JSON equals
/// `compare`'s on the written image.
#[test]
fn render_reference_and_compare_agree() {
    let dir = scratch_dir("compare-reference");
    let out = dir.join("r.exr");
    let reference = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/default_e1_200.exr");
    let o = photonmap(&[
        "--photons",
        "2e4",
        "--width",
        "200",
        "--height",
        "200",
        "--spp",
        "1",
        "--quiet",
        "--reference",
        reference.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rendered: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let v = json(&photonmap(&[
        "compare",
        out.to_str().unwrap(),
        reference.to_str().unwrap(),
        "--json",
        "--window",
        "173:193,126:157",
    ]));
    let close = |a: &serde_json::Value, b: &serde_json::Value| (a.as_f64().unwrap() - b.as_f64().unwrap()).abs() < 1e-6;
    assert!(close(&rendered["rmse"], &v["whole"]["rmse"]), "{rendered} vs {v}");
    assert!(close(&rendered["caustic_rmse"], &v["windows"][0]["rmse"]), "{rendered} vs {v}");
    assert!(close(&rendered["mean_x"], &v["whole"]["mean_test"]));
}

/// A reference holding NaN or infinity is refused with their count and the
/// first one's place; the scores once read NaN beside "non-finite values: 0".
#[test]
fn a_reference_with_non_finite_values_is_refused_with_their_count() {
    let dir = scratch_dir("compare-nan-reference");
    let test = exr(&dir, "test.exr", 6, 4, |_, _| 0.5);
    let reference = exr(&dir, "ref.exr", 6, 4, |x, y| match (x, y) {
        (2, 1) => f32::NAN,
        (5, 3) => f32::INFINITY,
        _ => 0.5,
    });
    for json in [false, true] {
        let mut args = vec!["compare", test.as_str(), reference.as_str()];
        if json {
            args.push("--json");
        }
        let o = photonmap(&args);
        let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(!o.status.success(), "accepted: {out}");
        assert!(!out.contains("NaN") && !out.contains("non-finite values: 0"), "{out}");
        // Grey pixels: three channels each.
        assert!(err.contains("reference holds 6 non-finite values") && err.contains("column 2, row 1"), "{err}");
    }
}

/// Against an all-black reference the relative bias is undefined: the
/// table says so instead of "+0.00%", the JSON holds null; the absolute
/// figures stay.
#[test]
fn the_bias_against_a_black_reference_is_undefined() {
    let dir = scratch_dir("compare-black-reference");
    let test = exr(&dir, "test.exr", 6, 4, |_, _| 0.25);
    let reference = exr(&dir, "ref.exr", 6, 4, |_, _| 0.0);
    let o = photonmap(&["compare", &test, &reference]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.contains("0.00%") && out.contains("undefined"), "{out}");
    assert!(out.contains("0.250000"), "the RMSE is still printed: {out}");
    let v = json(&photonmap(&["compare", &test, &reference, "--json"]));
    assert!(v["whole"]["bias"].is_null(), "{v}");
    assert!((v["whole"]["rmse"].as_f64().unwrap() - 0.25).abs() < 1e-6);
}
