//! `photonmap compare TEST.exr REF.exr`: a render's error against a
//! reference, with the metric of `crate::metrics`; with `--mitsuba-test`
//! and the reference's variance, Mitsuba 3's acceptance test instead.

use crate::error::Error;
use crate::metrics::mitsuba_test::{mitsuba_test, Verdict, PASSING_SHARE, SIGNIFICANCE};
use crate::metrics::{compare_images, diff_rgb8, Comparison, Region, Window};
use crate::output::{check_writable, read_exr, same_file, write_rgb8_image};
use std::path::{Path, PathBuf};

/// A comparison as the command line asks it.
pub struct Request {
    pub test: PathBuf,
    pub reference: PathBuf,
    /// The reference's per-pixel variance (Mitsuba's test).
    pub variance: Option<PathBuf>,
    /// Where the Mitsuba test draws its failing pixels.
    pub fail_map: Option<PathBuf>,
    pub windows: Vec<Window>,
    /// Where the signed difference picture goes, and its full intensity.
    pub diff: Option<PathBuf>,
    pub diff_scale: Option<f32>,
    pub json: bool,
}

/// Scores the test against the reference and prints the scores.
pub fn run(args: &Request) -> Result<(), Error> {
    let windows = &args.windows;
    if let Some(diff) = &args.diff {
        check_writable(diff)?;
        for input in [&args.test, &args.reference] {
            if same_file(diff, input) {
                return Err(Error::Invalid(format!("--diff {}: that is an input of the comparison", diff.display())));
            }
        }
    }
    let test = read_exr(&args.test)?;
    let reference = read_exr(&args.reference)?;
    let c = compare_images(&test, &reference, windows)
        .map_err(|e| Error::Invalid(format!("{} against {}: {e}", args.test.display(), args.reference.display())))?;
    let diff_scale = match &args.diff {
        Some(path) => {
            let reduced = crate::metrics::box_down(&test, c.factor);
            let (rgb, scale) = diff_rgb8(&reduced, &reference, args.diff_scale);
            write_rgb8_image(path, reference.width, reference.height, rgb)?;
            Some(scale)
        }
        None => None,
    };
    if args.json {
        println!("{}", json(&c, diff_scale));
    } else {
        print!("{}", table(&c, args, diff_scale));
    }
    Ok(())
}

fn region_json(r: &Region) -> serde_json::Value {
    serde_json::json!({
        "rmse": r.rmse,
        "relmse": r.relmse,
        "mean_test": r.mean_test,
        "mean_ref": r.mean_ref,
        "bias": r.relative_bias(),
        "pixels": r.pixels,
    })
}

fn json(c: &Comparison, diff_scale: Option<f32>) -> serde_json::Value {
    let windows: Vec<serde_json::Value> = c
        .windows
        .iter()
        .map(|(w, r)| {
            let mut v = region_json(r);
            v["name"] = w.name.clone().into();
            v["rows"] = serde_json::json!([w.rows.0, w.rows.1]);
            v["cols"] = serde_json::json!([w.cols.0, w.cols.1]);
            v
        })
        .collect();
    let mut v = serde_json::json!({
        "factor": c.factor,
        "whole": region_json(&c.whole),
        "windows": windows,
        "nan_count": c.nan_count,
        "speckles": c.speckles,
    });
    if let Some(s) = diff_scale {
        v["diff_scale"] = s.into();
    }
    v
}

fn table(c: &Comparison, args: &Request, diff_scale: Option<f32>) -> String {
    let mut out = String::new();
    let reduced = if c.factor > 1 { format!(" (test reduced {0}x{0})", c.factor) } else { String::new() };
    out += &format!("{} against {}{reduced}\n", args.test.display(), args.reference.display());
    out +=
        &format!("{:<12} {:>10} {:>10} {:>10} {:>10} {:>8}\n", "region", "rmse", "relmse", "mean", "ref mean", "bias");
    let row = |name: &str, r: &Region| {
        let bias = match r.relative_bias() {
            Some(b) => format!("{:>+7.2}%", 100.0 * b),
            None => "undefined".into(),
        };
        format!(
            "{:<12} {:>10.6} {:>10.6} {:>10.6} {:>10.6} {bias:>8}\n",
            name, r.rmse, r.relmse, r.mean_test, r.mean_ref
        )
    };
    out += &row("whole", &c.whole);
    for (w, r) in &c.windows {
        out += &row(&w.name, r);
    }
    if std::iter::once(&c.whole).chain(c.windows.iter().map(|(_, r)| r)).any(|r| r.relative_bias().is_none()) {
        out += "bias undefined: the reference's mean is 0 there, so no relative figure means anything\n";
    }
    let scored = if c.nan_count > 0 { " (scored as 0)" } else { "" };
    out += &format!("speckles: {} pixels; non-finite values in the test: {}{scored}\n", c.speckles, c.nan_count);
    if let (Some(path), Some(s)) = (&args.diff, diff_scale) {
        out += &format!("difference picture: {} (full intensity at {s:.4})\n", path.display());
    }
    out
}

/// Mitsuba 3's render-test acceptance (`crate::metrics::mitsuba_test`),
/// its verdict as an exit status: 0 accepted, 1 rejected, 2 when the test
/// cannot be run (an unreadable file, sizes that differ, a non-finite
/// reference, said on stderr), so that a script tells a rejected render
/// from a broken run as with `cmp` or `diff`.
pub fn mitsuba_status(args: &Request) -> u8 {
    match mitsuba(args) {
        Ok(true) => 0,
        Ok(false) => 1,
        Err(e) => {
            eprintln!("photonmap: error: {e}");
            2
        }
    }
}

/// Whether the image is accepted; prints the verdict and writes the map
/// of failing pixels when asked.
fn mitsuba(args: &Request) -> Result<bool, Error> {
    let variance_path =
        args.variance.as_deref().ok_or_else(|| Error::Invalid("--mitsuba-test needs IMAGE REF VARIANCE".into()))?;
    let inputs = [args.test.as_path(), args.reference.as_path(), variance_path];
    if let Some(map) = &args.fail_map {
        check_writable(map)?;
        if inputs.iter().any(|input| same_file(map, input)) {
            return Err(Error::Invalid(format!("--fail-map {}: that is an input of the test", map.display())));
        }
    }
    let [image, reference, variance] = inputs.map(read_exr);
    let (image, reference, variance) = (image?, reference?, variance?);
    let verdict = mitsuba_test(&image, &reference, &variance)
        .map_err(|e| Error::Invalid(format!("{} against {}: {e}", args.test.display(), args.reference.display())))?;
    if let Some(map) = &args.fail_map {
        write_rgb8_image(map, verdict.width, verdict.height, verdict.fail_map_rgb8(&image))?;
    }
    if args.json {
        println!("{}", verdict_json(&verdict, args.fail_map.as_deref()));
    } else {
        print!("{}", verdict_table(&verdict, args));
    }
    Ok(verdict.accepted)
}

fn verdict_json(v: &Verdict, fail_map: Option<&Path>) -> serde_json::Value {
    serde_json::json!({
        "accepted": v.accepted,
        "fraction_passing": v.fraction_passing,
        "passing_channels": v.passing_channels,
        "pixels": v.pixels(),
        "failing_pixels": v.failing_pixels(),
        "width": v.width,
        "height": v.height,
        "spp": v.spp,
        "level": v.level,
        "min_p": v.min_p,
        "mean_relative_error": v.mean_relative_error,
        "non_finite": v.non_finite,
        "fail_map": fail_map.map(|p| p.display().to_string()),
    })
}

fn verdict_table(v: &Verdict, args: &Request) -> String {
    let mut out = format!("{} against {} (Mitsuba 3's render test)\n", args.test.display(), args.reference.display());
    out += &format!(
        "{}x{} pixels: a budget of {} spp, a level of {:.4e} per pixel channel (Sidak, {}% over {} pixels)\n",
        v.width,
        v.height,
        v.spp,
        v.level,
        100.0 * SIGNIFICANCE,
        v.pixels()
    );
    out += &format!(
        "passing: {:.4}% of pixel channels ({} of {}; at least {:.2}% needed); failing pixels: {}\n",
        100.0 * v.fraction_passing,
        v.passing_channels,
        3 * v.pixels(),
        100.0 * PASSING_SHARE,
        v.failing_pixels()
    );
    out += &format!("smallest p-value: {:.4e}\n", v.min_p);
    out += &match v.mean_relative_error {
        Some(e) => format!("error of the mean (XYZ): {:.4}%\n", 100.0 * e),
        None if v.non_finite > 0 => "error of the mean: undefined (the image holds non-finite values)\n".into(),
        None => "error of the mean: undefined (the reference's mean is 0)\n".into(),
    };
    if v.non_finite > 0 {
        out +=
            &format!("non-finite values in the image: {} (their pixels fail; the image is rejected)\n", v.non_finite);
    }
    if let Some(map) = &args.fail_map {
        out += &format!("failing pixels: {} (red)\n", map.display());
    }
    out += if v.accepted { "accepted\n" } else { "rejected\n" };
    out
}
