//! Integrators: turn a camera ray into radiance.
//!
//! * [`photon`]: Jensen's photon-mapping estimator (classic and progressive);
//! * [`path`]: path tracing with next-event estimation, the unbiased reference;
//! * [`whitted`]: the CS475 Whitted ray tracer;
//! * [`unseen`]: what of a scene's light a path tracer cannot find.
//!
//! All run on the same camera pass (`render::camera_pass`), which owns the
//! pixel loop and the random streams; an integrator answers one camera ray
//! at a time and keeps whatever state of its own it needs in the two
//! associated types.

mod aim;
mod direct;
pub mod mis;
pub mod path;
pub mod photon;
pub mod unseen;
pub mod volgather;
pub mod volpath;
pub mod volphoton;
pub mod whitted;

pub use direct::{
    direct_irradiance, direct_light, direct_light_mis, direct_light_one_at_a_time, direct_light_shared, MisBsdf,
};

use crate::math::{Color, Ray};
use crate::sampling::Rng;
use crate::stats::Counters;

/// Which part of the radiance a camera sample estimates. A pixel's value is
/// the sum of what reaches the eye from a light's own surface (directly or
/// through mirrors and glass: paths E S* L) and everything else; the two can
/// be estimated with different numbers of samples, because the first is
/// cheap and, at the rim of a light's image, has most of the variance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    All,
    /// Emitted radiance seen along specular chains only (diffuse hits are dark).
    Emitted,
    /// Everything but the emitted part.
    Reflected,
}

/// A camera-ray estimator.
pub trait Integrator: Sync {
    /// What a thread keeps from one ray to the next (scratch space); made
    /// once per thread, so it never decides a pixel's value.
    type Thread: Default + Send;
    /// What one pixel's samples share, and only they: made fresh at every
    /// pixel, so a pixel's value never depends on which thread rendered it
    /// or on the pixels before.
    type Pixel: Default;

    /// Radiance arriving along a camera ray (towards its origin), less
    /// what it left for [`Self::finish`].
    fn radiance(
        &self,
        ray: Ray,
        part: Part,
        ctx: &mut Context,
        thread: &mut Self::Thread,
        pixel: &mut Self::Pixel,
    ) -> Color;

    /// The radiance the samples since the last call left for later; the
    /// camera pass calls it after each run of a pixel's samples.
    fn finish(&self, _ctx: &mut Context, _thread: &mut Self::Thread, _pixel: &mut Self::Pixel) -> Color {
        Color::ZERO
    }

    /// Tells the pixel which of its samples comes next: its place
    /// `index` in the pixel's sequence over all passes, and the pixel's
    /// own `scramble` (the same in every pass), for an estimator that
    /// draws from a sequence continued from pass to pass.
    fn start_sample(&self, _pixel: &mut Self::Pixel, _index: u64, _scramble: u64) {}
}

/// What every integrator's sample has: its random stream, the thread's
/// counters, and the pixel it belongs to (for messages).
pub struct Context<'r> {
    pub rng: &'r mut Rng,
    pub counters: &'r mut Counters,
    pub pixel: u64,
}

impl Context<'_> {
    /// Passes a finite estimate through; counts and drops a non-finite one,
    /// remembering the first (pixel, estimator). Debug builds stop there.
    pub fn checked(&mut self, c: Color, estimator: &'static str) -> Color {
        debug_assert!(c.is_finite(), "{estimator} estimate {c} at pixel {}", self.pixel);
        if c.is_finite() {
            c
        } else {
            self.counters.nonfinite += 1;
            self.counters.note_nonfinite(self.pixel, estimator);
            Color::ZERO
        }
    }
}
