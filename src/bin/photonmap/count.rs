//! A count option's value (`--spp 1e3`, `--passes 256`, `--width 800`):
//! every count takes the notation --photons takes, a whole number written
//! plainly or in e-notation, within the option's range; and a seed. Shared
//! by both programs.

use clap::builder::TypedValueParser;
use clap::error::ErrorKind;
use std::ffi::OsStr;

/// A whole number from `lo` to `hi`.
#[derive(Clone, Copy, Debug)]
pub struct Count {
    lo: u32,
    hi: u32,
}

/// The parser of a count from `lo` to `hi`, for `value_parser = count(..)`.
pub const fn count(lo: u32, hi: u32) -> Count {
    Count { lo, hi }
}

impl Count {
    /// The value, or what is wrong with it.
    pub fn parse(&self, s: &str) -> Result<u32, String> {
        let v: f64 = s.trim().parse().map_err(|_| format!("'{s}' is not a number (try 1e3 or 1000)"))?;
        let range = format!("from {} to {}", self.lo, self.hi);
        if !v.is_finite() || v.fract() != 0.0 {
            return Err(format!("'{s}' must be a whole number {range}"));
        }
        if v < self.lo as f64 || v > self.hi as f64 {
            return Err(format!("'{s}' is not {range}"));
        }
        Ok(v as u32)
    }
}

/// A seed: any 64-bit whole number.
pub fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| format!("'{s}' must be a whole number from 0 to {}", u64::MAX))
}

impl TypedValueParser for Count {
    type Value = u32;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<u32, clap::Error> {
        let text = value.to_string_lossy();
        self.parse(&text).map_err(|why| {
            let name = arg.map_or_else(|| "the value".to_string(), |a| a.to_string());
            clap::Error::raw(ErrorKind::ValueValidation, format!("invalid value '{text}' for '{name}': {why}\n"))
                .with_cmd(cmd)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_and_e_notation_are_the_same_count() {
        let c = count(1, 1_000_000);
        assert_eq!(c.parse("1e3"), Ok(1000));
        assert_eq!(c.parse("1000"), Ok(1000));
        assert_eq!(c.parse("2.5e2"), Ok(250));
        assert_eq!(c.parse("1e6"), Ok(1_000_000));
        assert!(c.parse("1e9").unwrap_err().contains("is not from 1 to 1000000"));
        assert!(c.parse("0").unwrap_err().contains("is not from 1"));
        assert!(c.parse("1.5").unwrap_err().contains("whole number"));
        assert!(c.parse("-3").unwrap_err().contains("is not from 1"));
        assert!(c.parse("abc").unwrap_err().contains("not a number"));
        assert!(c.parse("inf").unwrap_err().contains("whole number"));
    }
}
