//! Option values shared by the commands: the library's tables by name
//! (the parsers of single values are `photonmap::command::values`).

use clap::builder::PossibleValue;
use clap::ValueEnum;
pub use photonmap::command::values::*;
use photonmap::film::ToneMap;
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
