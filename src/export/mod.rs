//! Scenes written for other renderers, so that photonmap's image can be put
//! beside theirs on the same scene: Mitsuba 3 ([`mitsuba`]).

pub mod mitsuba;
mod mitsuba_bsdf;
mod mitsuba_medium;
mod mitsuba_recipe;
mod mitsuba_sensor;
mod ply;
