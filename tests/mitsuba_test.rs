//! `photonmap compare --mitsuba-test`: Mitsuba 3's render-test acceptance
//! through the command line agrees with the Python version of the test
//! (shared/refs/mitsuba_tests/ztest.py, numpy in double precision) on
//! images made here: a reference, its variance, the reference plus noise
//! of the variance's size (accepted), the same ×1.02 (rejected), the same
//! with one NaN (rejected though its share of passing pixels is enough).

mod common;
use common::{photonmap, scratch_dir};
use photonmap::film::Film;
use photonmap::math::Color;
use photonmap::metrics::mitsuba_test::spp_budget;
use photonmap::output::write;
use std::path::{Path, PathBuf};

const W: u32 = 32;
const H: u32 = 24;

/// A uniform number in (0, 1) from an index (splitmix64's finaliser): the
/// same noise on every machine, without a generator's state.
fn uniform(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9e37_79b9_7f4a_7c15).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 30)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
}

/// A standard normal number (Box–Muller) from an index.
fn gaussian(i: u64) -> f64 {
    let (u, v) = (uniform(2 * i), uniform(2 * i + 1));
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

fn film(f: impl Fn(u32, u32, usize) -> f32) -> Film {
    Film {
        width: W,
        height: H,
        pixels: (0..W * H).map(|i| Color::from_array([0, 1, 2].map(|c| f(i % W, i / W, c)))).collect(),
    }
}

fn reference() -> Film {
    film(|x, y, c| match c {
        0 => 0.2 + 0.6 * x as f32 / (W - 1) as f32,
        1 => 0.1 + 0.5 * y as f32 / (H - 1) as f32,
        _ if y == 0 => 0.0,
        _ => 0.3 + 0.05 * ((x + y) % 5) as f32,
    })
}

/// The reference's variance: a 2% error shows in some pixels, not all; a row
/// of zeros and a few negative values (Mitsuba's references have them, from
/// converting their XYZ variance to RGB) meet the floor of 1e-4.
fn variance(reference: &Film) -> Film {
    film(|x, y, c| match (x, y) {
        (_, 2) => 0.0,
        (x, 5) if x % 7 == 0 => -0.01,
        _ => 0.02 * reference.get(x, y).to_array()[c],
    })
}

/// The reference plus normal noise of its variance over the test's spp,
/// each RGB channel on its own: in XYZ that noise is smaller than the
/// variance the test assumes (the test converts variance as a colour), so
/// it passes.
fn noisy(reference: &Film, variance: &Film) -> Film {
    let spp = spp_budget((W * H) as u64) as f64;
    film(|x, y, c| {
        let (r, v) = (reference.get(x, y).to_array()[c] as f64, variance.get(x, y).to_array()[c] as f64);
        (r + gaussian(((y * W + x) * 3 + c as u32) as u64) * (v.max(1e-4) / spp).sqrt()) as f32
    })
}

fn scaled(film: &Film, s: f32) -> Film {
    Film { pixels: film.pixels.iter().map(|&c| c * s).collect(), ..film.clone() }
}

/// The files: reference, variance, and the images under test by name.
fn write_images(dir: &Path) -> (String, String, Vec<(&'static str, String)>) {
    let path = |name: &str, f: &Film| {
        let p = dir.join(name);
        write(&p, f, Default::default(), 1.0).unwrap();
        p.to_str().unwrap().to_string()
    };
    let r = reference();
    let v = variance(&r);
    let n = noisy(&r, &v);
    let mut with_nan = n.clone();
    with_nan.pixels[(7 * W + 11) as usize].y = f32::NAN;
    let images = vec![
        ("same", path("same.exr", &r)),
        ("noisy", path("noisy.exr", &n)),
        ("noisy_x1.02", path("noisy_x102.exr", &scaled(&n, 1.02))),
        ("noisy_nan", path("noisy_nan.exr", &with_nan)),
    ];
    (path("ref.exr", &r), path("var.exr", &v), images)
}

fn verdict(image: &str, reference: &str, variance: &str) -> (i32, serde_json::Value) {
    let o = photonmap(&["compare", "--mitsuba-test", image, reference, variance, "--json"]);
    let v = serde_json::from_slice(&o.stdout)
        .unwrap_or_else(|_| panic!("no JSON from {image}: {}", String::from_utf8_lossy(&o.stderr)));
    (o.status.code().expect("an exit code"), v)
}

/// What ztest.py printed for each image (its `accepted`, `pixels_passing`,
/// `min_p` and `mean_rel_err`), run by hand on the files this test writes
/// (python 3.11, numpy 2.4.6, the OpenEXR 3.5.3 bindings). ztest.py rounds
/// the fraction and the error to five decimals; its `min_p` and error of
/// the NaN image are NaN, where ours are 0 (a non-finite value counts as
/// p = 0) and undefined. A p-value of 0 is one below the smallest double
/// (the floored variance of row 2 makes z enormous).
const ZTEST: [(&str, bool, f64, f64, f64); 4] = [
    ("same", true, 1.0, 1.0, 0.0),
    ("noisy", true, 1.0, 0.00012320181487613803, 4e-05),
    ("noisy_x1.02", false, 0.40191, 0.0, 0.01996),
    ("noisy_nan", false, 0.9987, f64::NAN, f64::NAN),
];

/// Our verdict (JSON) against ztest.py's figures for the same image.
fn assert_agrees(name: &str, ours: &serde_json::Value, accepted: bool, fraction: f64, min_p: f64, mean_error: f64) {
    assert_eq!(ours["accepted"], accepted, "{name}: {ours}");
    let f = ours["fraction_passing"].as_f64().unwrap();
    // Five decimals: within half a unit of the fifth, and a hair.
    assert!((f - fraction).abs() <= 5.000_001e-6, "{name}: fraction {f} against {fraction}");
    let p = ours["min_p"].as_f64().unwrap();
    if min_p.is_nan() {
        assert!(p == 0.0 && ours["non_finite"].as_u64().unwrap() > 0, "{name}: {ours}");
    } else {
        assert!((p - min_p).abs() <= 1e-6 * min_p, "{name}: min p {p:e} against {min_p:e}");
    }
    match ours["mean_relative_error"].as_f64() {
        Some(e) => assert!((e - mean_error).abs() <= 5.000_001e-6, "{name}: mean error {e} against {mean_error}"),
        None => assert!(mean_error.is_nan(), "{name}: the error of the mean is undefined: {ours}"),
    }
}

#[test]
fn the_verdicts_agree_with_the_python_test() {
    let dir = scratch_dir("mitsuba-test-agree");
    let (reference, variance, images) = write_images(&dir);
    for ((name, image), (zname, accepted, fraction, min_p, mean_error)) in images.iter().zip(ZTEST) {
        assert_eq!(*name, zname);
        let (code, v) = verdict(image, &reference, &variance);
        assert_agrees(name, &v, accepted, fraction, min_p, mean_error);
        assert_eq!(code, if accepted { 0 } else { 1 }, "{name}: exit status");
        assert_eq!(v["spp"], 2_000_000 / (W * H), "{name}");
        let level = 1.0 - 0.99f64.powf(1.0 / (W * H) as f64);
        assert!((v["level"].as_f64().unwrap() / level - 1.0).abs() < 1e-9, "{name}");
    }
}

/// Where python with numpy and the OpenEXR bindings is installed (not on
/// CI), the Python test itself runs on the same files: the recorded
/// figures above are what it says.
#[test]
fn the_figures_agree_with_the_python_test_where_it_can_run() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/refs/mitsuba_tests/ztest.py");
    let python_ready = std::process::Command::new("python3")
        .args(["-c", "import numpy, OpenEXR, Imath"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !script.is_file() || !python_ready {
        eprintln!("skipped: needs {} and python3 with numpy and OpenEXR", script.display());
        return;
    }
    let dir = scratch_dir("mitsuba-test-python");
    let (reference, variance, images) = write_images(&dir);
    for (name, image) in &images {
        let (code, ours) = verdict(image, &reference, &variance);
        let o =
            std::process::Command::new("python3").arg(&script).args([image, &reference, &variance]).output().unwrap();
        let text = String::from_utf8_lossy(&o.stdout).replace("NaN", "null");
        let theirs: serde_json::Value =
            serde_json::from_str(&text).unwrap_or_else(|_| panic!("ztest.py on {name}: {text}"));
        let number = |key: &str| theirs[key].as_f64().unwrap_or(f64::NAN);
        let accepted = theirs["accepted"].as_bool().unwrap();
        assert_agrees(name, &ours, accepted, number("pixels_passing"), number("min_p"), number("mean_rel_err"));
        assert_eq!(code, o.status.code().unwrap(), "{name}: exit status");
        assert_eq!(ours["spp"], theirs["spp_budget"], "{name}");
        assert!((ours["level"].as_f64().unwrap() / number("alpha") - 1.0).abs() < 1e-9, "{name}");
    }
}

/// Sizes that differ, an unreadable file and a non-finite reference are
/// errors (exit 2) that name what is wrong, with no verdict printed.
#[test]
fn inputs_the_test_cannot_use_are_refused() {
    let dir = scratch_dir("mitsuba-test-refused");
    let (reference, variance, images) = write_images(&dir);
    let image = &images[1].1;
    let small = dir.join("small.exr");
    write(&small, &Film::new(W, H - 1), Default::default(), 1.0).unwrap();
    let mut nan_ref = self::reference();
    nan_ref.pixels[3].x = f32::INFINITY;
    let nan_ref_path = dir.join("nan_ref.exr");
    write(&nan_ref_path, &nan_ref, Default::default(), 1.0).unwrap();
    let missing = dir.join("missing.exr");
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    for (args, says) in [
        ([s(&small), reference.clone(), variance.clone()], "32x23 but the reference is 32x24"),
        ([image.clone(), reference.clone(), s(&small)], "variance image is 32x23"),
        ([image.clone(), s(&missing), variance.clone()], "missing.exr"),
        ([image.clone(), s(&nan_ref_path), variance.clone()], "reference holds 1 non-finite value"),
    ] {
        let o = photonmap(&["compare", "--mitsuba-test", &args[0], &args[1], &args[2]]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
    // Without --mitsuba-test a third image is not taken.
    let o = photonmap(&["compare", image, &reference, &variance]);
    assert!(!o.status.success());
}

/// The map of failing pixels is written at the test's size, red where a
/// pixel fails; it may not replace an input.
#[test]
fn the_fail_map_marks_the_failing_pixels_and_never_replaces_an_input() {
    let dir = scratch_dir("mitsuba-test-map");
    let (reference, variance, images) = write_images(&dir);
    let image = &images[3].1; // one NaN at column 11, row 7
    let map = dir.join("failing.png");
    let map_s = map.to_str().unwrap();
    let o = photonmap(&["compare", "--mitsuba-test", image, &reference, &variance, "--fail-map", map_s]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("rejected") && text.contains("non-finite values in the image: 1"), "{text}");
    assert!(!text.contains("NaN"), "{text}");
    let png = image::open(&map).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (W, H));
    let red: Vec<(u32, u32)> =
        png.enumerate_pixels().filter(|(_, _, p)| p.0 == [255, 0, 0]).map(|(x, y, _)| (x, y)).collect();
    assert_eq!(red, vec![(11, 7)]);
    for input in [image.as_str(), &reference, &variance] {
        let before = std::fs::read(input).unwrap();
        let o = photonmap(&["compare", "--mitsuba-test", image, &reference, &variance, "--fail-map", input]);
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains("input"), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(std::fs::read(input).unwrap(), before, "{input} was changed");
    }
}
