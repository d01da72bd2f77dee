//! A count option's value (`--spp 1e3`, `--passes 256`, `--width 800`):
//! every count takes the notation --photons takes, a whole number written
//! plainly or in e-notation, within the option's range; and a seed. Shared
//! by both programs.

use clap::builder::TypedValueParser;
use clap::error::ErrorKind;
pub use photonmap::command::values::parse_seed;
use photonmap::command::values::parse_whole;
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

impl TypedValueParser for Count {
    type Value = u32;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<u32, clap::Error> {
        let text = value.to_string_lossy();
        parse_whole(&text, self.lo, self.hi).map_err(|why| {
            let name = arg.map_or_else(|| "the value".to_string(), |a| a.to_string());
            clap::Error::raw(ErrorKind::ValueValidation, format!("invalid value '{text}' for '{name}': {why}\n"))
                .with_cmd(cmd)
        })
    }
}
