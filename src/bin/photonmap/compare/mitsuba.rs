//! `photonmap compare --mitsuba-test IMAGE REF VAR`: Mitsuba 3's render-test
//! acceptance (`photonmap::metrics::mitsuba_test`), its verdict as the exit
//! status: 0 accepted, 1 rejected, 2 when the test cannot be run (an
//! unreadable file, sizes that differ, a non-finite reference), so that a
//! script tells a rejected render from a broken run as with `cmp` or `diff`.

use super::Args;
use photonmap::error::Error;
use photonmap::metrics::mitsuba_test::{mitsuba_test, Verdict, PASSING_SHARE, SIGNIFICANCE};
use photonmap::output::{check_writable, read_exr, same_file, write_rgb8_image};
use std::io::Write;
use std::path::Path;

/// Runs the test and exits with its verdict; never returns.
pub fn run(args: &Args) -> ! {
    let code = match test(args) {
        Ok(true) => 0,
        Ok(false) => 1,
        Err(e) => {
            eprintln!("photonmap: error: {e}");
            2
        }
    };
    let _ = std::io::stdout().flush();
    std::process::exit(code)
}

/// Whether the image is accepted; prints the verdict and writes the map
/// of failing pixels when asked.
fn test(args: &Args) -> Result<bool, Error> {
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
        println!("{}", json(&verdict, args.fail_map.as_deref()));
    } else {
        print!("{}", table(&verdict, args));
    }
    Ok(verdict.accepted)
}

pub fn json(v: &Verdict, fail_map: Option<&Path>) -> serde_json::Value {
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

fn table(v: &Verdict, args: &Args) -> String {
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
