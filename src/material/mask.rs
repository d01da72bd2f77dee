//! Mitsuba 3's `mask` over a diffuse BSDF (src/bsdfs/mask.cpp): with
//! probability `opacity` the surface is its diffuse BSDF, otherwise light
//! passes straight through, unchanged, as if the surface were not there
//! (a leaf cut out of a rectangle by an image). The pass-through is a
//! specular branch: rays follow it, and shadow rays stop at the surface,
//! as Mitsuba's do.

use crate::math::Color;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Masked {
    /// In [0, 1].
    pub opacity: f32,
    /// The diffuse BSDF's reflectance (black on the back of a one-sided one).
    pub rho: Color,
}

impl Masked {
    /// The diffuse lobe's reflectance, the opaque share of the surface's.
    pub fn rho(&self) -> Color {
        self.rho * self.opacity
    }

    /// The share of light that passes through.
    pub fn through(&self) -> f32 {
        1.0 - self.opacity
    }
}
