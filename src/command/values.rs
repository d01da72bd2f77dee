//! What a valid value of a command-line option is, and what to say when it
//! is not: the limits belong to the library (a map's photon capacity, a
//! budget's longest run), so the programs only hand their text here.

use crate::metrics::Window;

/// A whole number from `lo` to `hi`, written plainly or in e-notation
/// (`--spp 1e3`, `--passes 256`), as every count option takes it.
pub fn parse_whole(s: &str, lo: u32, hi: u32) -> Result<u32, String> {
    let v: f64 = s.trim().parse().map_err(|_| format!("'{s}' is not a number (try 1e3 or 1000)"))?;
    let range = format!("from {lo} to {hi}");
    if !v.is_finite() || v.fract() != 0.0 {
        return Err(format!("'{s}' must be a whole number {range}"));
    }
    if v < lo as f64 || v > hi as f64 {
        return Err(format!("'{s}' is not {range}"));
    }
    Ok(v as u32)
}

/// A seed: any 64-bit whole number.
pub fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| format!("'{s}' must be a whole number from 0 to {}", u64::MAX))
}

/// A photon count: an integer written plainly or in e-notation.
pub fn parse_count(s: &str) -> Result<u64, String> {
    let v: f64 = s.trim().parse().map_err(|_| format!("'{s}' is not a number (try 1e6 or 250000)"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("'{s}' must be zero or a positive count"));
    }
    if v.fract() != 0.0 {
        return Err(format!("'{s}' is not a whole number of photons"));
    }
    // Photon indices are 32-bit in the kd-tree; beyond this the maps would
    // not fit in memory on any machine this runs on anyway.
    const MAX: f64 = 1e9;
    if v > MAX {
        return Err(format!("'{s}' is more than the 1e9 photons a map can hold"));
    }
    Ok(v as u64)
}

/// A search radius, in scene units.
pub fn parse_radius(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive distance")),
    }
}

/// A fraction from 0 to 1 (`--caustic-reuse`).
pub fn parse_fraction(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' must be a number from 0 to 1")),
    }
}

/// A week is the longest run a budget may ask for.
const MAX_SECONDS: f64 = 7.0 * 24.0 * 3600.0;

/// A time budget: positive, at most a week.
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= MAX_SECONDS => Ok(v),
        Ok(v) if v > MAX_SECONDS => Err(format!("'{s}' is more than a week ({MAX_SECONDS} s)")),
        _ => Err(format!("'{s}' must be a positive number of seconds")),
    }
}

/// Progressive photon mapping's alpha, strictly between 0 and 1.
pub fn parse_alpha(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("'{s}' must lie strictly between 0 and 1")),
    }
}

/// A brightness factor of 8-bit outputs.
pub fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive factor")),
    }
}

/// A relative error: 0.02 is 2%.
pub fn parse_target(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("'{s}' must be a relative error between 0 and 1 (0.02 is 2%)")),
    }
}

/// Every `--window` (`[NAME=]R0:R1,C0:C1`), in order.
pub fn parse_windows(texts: &[String]) -> Result<Vec<Window>, String> {
    texts
        .iter()
        .enumerate()
        .map(|(i, w)| Window::parse(w, i))
        .collect::<Result<_, _>>()
        .map_err(|e| format!("--window: {e}"))
}

/// `NAME=VALUE` for -D: a parameter name is letters, digits and `_`.
pub fn parse_define(s: &str) -> Result<(String, String), String> {
    let (name, value) = s.split_once('=').ok_or_else(|| format!("'{s}' is not NAME=VALUE"))?;
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!("'{name}' is not a parameter name (letters, digits and _)"));
    }
    Ok((name.to_string(), value.to_string()))
}

/// The scale of a difference image (`compare --diff-scale`).
pub fn parse_difference(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive difference")),
    }
}

/// A point `X,Y,Z` of three finite numbers (`export --origin`).
pub fn parse_point(text: &str) -> Result<glam::Vec3, String> {
    let v: Vec<f32> = text
        .split(',')
        .map(|c| c.trim().parse::<f32>().map_err(|e| format!("{c:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(glam::Vec3::new(*x, *y, *z)),
        _ => Err("give three finite numbers, X,Y,Z".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_and_e_notation_are_the_same_count() {
        let c = |s| parse_whole(s, 1, 1_000_000);
        assert_eq!(c("1e3"), Ok(1000));
        assert_eq!(c("1000"), Ok(1000));
        assert_eq!(c("2.5e2"), Ok(250));
        assert_eq!(c("1e6"), Ok(1_000_000));
        assert!(c("1e9").unwrap_err().contains("is not from 1 to 1000000"));
        assert!(c("0").unwrap_err().contains("is not from 1"));
        assert!(c("1.5").unwrap_err().contains("whole number"));
        assert!(c("-3").unwrap_err().contains("is not from 1"));
        assert!(c("abc").unwrap_err().contains("not a number"));
        assert!(c("inf").unwrap_err().contains("whole number"));
    }

    #[test]
    fn photon_counts_take_e_notation_up_to_a_maps_capacity() {
        assert_eq!(parse_count("2.5e5"), Ok(250_000));
        assert_eq!(parse_count("0"), Ok(0));
        assert!(parse_count("2e9").unwrap_err().contains("1e9 photons"));
        assert!(parse_count("1.5").unwrap_err().contains("whole number"));
    }

    #[test]
    fn points_need_three_finite_numbers() {
        assert_eq!(parse_point("1, -2,3"), Ok(glam::Vec3::new(1.0, -2.0, 3.0)));
        assert!(parse_point("1,2").is_err());
        assert!(parse_point("1,2,inf").is_err());
    }
}
