//! What the programs' commands do, their flags parsed: each takes a
//! request and runs it, and the programs (`src/bin/`) only parse their
//! command lines into requests and choose the observers of a render.
//!
//! * [`render`]: photonmap's render (classic, progressive, a range of
//!   passes, on from a partial), with [`load`], [`checks`],
//!   [`observers`], [`outputs`] and [`summary`];
//! * [`merge`]: partial renders added into one image;
//! * [`trace`]: the Whitted tracer's render;
//! * [`values`]: what a valid option value is.

pub mod checks;
pub mod compare;
pub mod export;
pub mod info;
pub mod load;
pub mod merge;
pub mod observers;
pub mod outputs;
pub mod render;
pub mod summary;
pub mod trace;
pub mod values;
