//! Option values shared by the commands: parsers that say what is wrong
//! with a value, the library's tables by name, windows.

use clap::builder::PossibleValue;
use clap::ValueEnum;
use photonmap::film::ToneMap;
use photonmap::metrics::Window;
use photonmap::render::Method;
use std::sync::LazyLock;

/// A value of one of the library's tables, by its name: the render
/// methods that estimate radiance (`--integrator`), the tone maps
/// (`--tonemap`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Named<T>(pub T);

pub trait Table: Copy + Send + Sync + Sized + 'static {
    fn entries() -> &'static [Named<Self>];
    fn name(self) -> &'static str;
    fn help(self) -> &'static str;
}

impl<T: Table> ValueEnum for Named<T> {
    fn value_variants<'a>() -> &'a [Self] {
        T::entries()
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.0.name()).help(self.0.help()))
    }
}

impl Table for Method {
    fn entries() -> &'static [Named<Method>] {
        static E: LazyLock<Vec<Named<Method>>> =
            LazyLock::new(|| Method::ALL.into_iter().filter(|m| m.estimates_radiance()).map(Named).collect());
        &E
    }
    fn name(self) -> &'static str {
        Method::name(self)
    }
    fn help(self) -> &'static str {
        self.description()
    }
}

impl Table for ToneMap {
    fn entries() -> &'static [Named<ToneMap>] {
        static E: LazyLock<Vec<Named<ToneMap>>> = LazyLock::new(|| ToneMap::ALL.into_iter().map(Named).collect());
        &E
    }
    fn name(self) -> &'static str {
        ToneMap::name(self)
    }
    fn help(self) -> &'static str {
        self.description()
    }
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

pub fn parse_radius(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' must be a positive distance")),
    }
}

pub fn parse_fraction(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' must be a number from 0 to 1")),
    }
}

/// A week is the longest run a budget may ask for.
const MAX_SECONDS: f64 = 7.0 * 24.0 * 3600.0;

pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= MAX_SECONDS => Ok(v),
        Ok(v) if v > MAX_SECONDS => Err(format!("'{s}' is more than a week ({MAX_SECONDS} s)")),
        _ => Err(format!("'{s}' must be a positive number of seconds")),
    }
}

pub fn parse_alpha(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("'{s}' must lie strictly between 0 and 1")),
    }
}

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
