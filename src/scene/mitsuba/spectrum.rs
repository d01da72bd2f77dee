//! Mitsuba's colours in RGB, the way its RGB variants read them (so that a
//! scene renders as Mitsuba's `scalar_rgb` renders it):
//!
//! * `<rgb>` is linear sRGB, taken as it is;
//! * a uniform `<spectrum value="v">` is `v` for a reflectance, but for an
//!   emitter it is `v` times the sRGB of the equal-energy spectrum
//!   (XYZ = (1, 1, 1)): a flat spectrum is not white under sRGB's D65;
//! * wavelength:value pairs are integrated against the CIE 1931 observer
//!   (linearly interpolated between the given wavelengths, zero outside
//!   them), under D65 for a reflectance and alone for an emitter, then
//!   turned into linear sRGB and clamped (a reflectance to [0, 1], an
//!   emission to >= 0).
//!
//! The integration's rule (1000 midpoint-free steps over 360-830 nm, the
//! luminance scale 1 / 106.75...) and the XYZ-to-sRGB matrix are the ones
//! Mitsuba 3 documents and uses for `spectrum_list_to_srgb`
//! (src/core/spectrum.cpp), so that the same file gives the same colour.

use super::cie;
use crate::math::Color;

/// XYZ to linear sRGB (IEC 61966-2-1, D65 white), the matrix Mitsuba uses.
const XYZ_TO_SRGB: [[f64; 3]; 3] =
    [[3.240479, -1.537150, -0.498535], [-0.969256, 1.875991, 0.041556], [0.055648, -0.204043, 1.057311]];

/// Makes the CIE y-bar integrate to 1 over the tables' range.
const Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;
/// Makes D65 against y-bar integrate to a luminance of 1.
const D65_NORMALIZATION: f64 = 1.0 / 98.99741751876255;

pub fn xyz_to_srgb(xyz: [f64; 3]) -> [f64; 3] {
    let m = XYZ_TO_SRGB;
    [0, 1, 2].map(|i| m[i][0] * xyz[0] + m[i][1] * xyz[1] + m[i][2] * xyz[2])
}

/// Linear interpolation in a table sampled every 5 nm from `cie::MIN`.
fn table(t: &[f64; cie::SAMPLES], w: f64) -> f64 {
    if !(cie::MIN..=cie::MAX).contains(&w) {
        return 0.0;
    }
    let x = (w - cie::MIN) * ((cie::SAMPLES - 1) as f64 / (cie::MAX - cie::MIN));
    let i0 = (x as usize).min(cie::SAMPLES - 2);
    let f = x - i0 as f64;
    (1.0 - f) * t[i0] + f * t[i0 + 1]
}

/// What a colour is for: reflectances are bounded to [0, 1] and seen under
/// D65; emission is unbounded and seen alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    Reflectance,
    Emission,
    /// A positive quantity that is no reflectance (an index of refraction,
    /// an absorption): unbounded, under D65.
    Unbounded,
}

/// A uniform spectrum of value `v`.
pub fn uniform(v: f64, usage: Use) -> Color {
    match usage {
        Use::Emission => {
            let c = xyz_to_srgb([1.0, 1.0, 1.0]);
            Color::new((v * c[0]) as f32, (v * c[1]) as f32, (v * c[2]) as f32)
        }
        _ => Color::splat(v as f32),
    }
}

/// Wavelength:value pairs (wavelengths increasing, in nm) as RGB, as
/// Mitsuba's RGB variants compute it. Also says whether a reflectance had
/// to be clamped into [0, 1] (Mitsuba clamps it with a warning).
pub fn pairs_to_rgb(wavelengths: &[f64], values: &[f64], usage: Use) -> (Color, bool) {
    const STEPS: usize = 1000;
    let mut xyz = [0.0f64; 3];
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    for i in 0..STEPS {
        let w = cie::MIN + (i as f64 / (STEPS - 1) as f64) * (cie::MAX - cie::MIN);
        if w < first || w > last {
            continue;
        }
        // The interval [w_k, w_k+1] holding w (the last one at the end).
        let k = wavelengths.partition_point(|&x| x <= w).saturating_sub(1).min(wavelengths.len().saturating_sub(2));
        let v = if wavelengths.len() == 1 {
            values[0]
        } else {
            let (w0, w1, v0, v1) = (wavelengths[k], wavelengths[k + 1], values[k], values[k + 1]);
            ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1)
        };
        let light = match usage {
            Use::Emission => 1.0,
            _ => table(&cie::D65, w) * D65_NORMALIZATION,
        };
        xyz[0] += table(&cie::X, w) * v * light;
        xyz[1] += table(&cie::Y, w) * v * light;
        xyz[2] += table(&cie::Z, w) * v * light;
    }
    let scale = (cie::MAX - cie::MIN) * Y_NORMALIZATION / STEPS as f64;
    let rgb = xyz_to_srgb(xyz.map(|c| c * scale));
    let (lo, hi) = match usage {
        Use::Reflectance => (0.0, 1.0),
        _ => (0.0, f64::INFINITY),
    };
    let clamped = rgb.iter().any(|&c| c < lo || c > hi);
    let c = rgb.map(|c| c.clamp(lo, hi) as f32);
    (Color::new(c[0], c[1], c[2]), clamped)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The D65 illuminant's own spectrum, seen as a reflectance of 1
    /// everywhere, is white: the tables and the matrix agree.
    #[test]
    fn a_flat_reflectance_is_white_and_a_flat_emission_is_not() {
        let w: Vec<f64> = (0..95).map(|i| 360.0 + 5.0 * i as f64).collect();
        let (c, clamped) = pairs_to_rgb(&w, &vec![0.5; 95], Use::Reflectance);
        for ch in c.to_array() {
            assert!((ch - 0.5).abs() < 0.01, "{c}");
        }
        assert!(!clamped);
        // An equal-energy emission is not white under sRGB's D65: its
        // XYZ (1, 1, 1) is (1.2048, 0.9484, 0.9086) in linear sRGB.
        let e = uniform(1.0, Use::Emission);
        assert!((e - Color::new(1.204794, 0.948292, 0.908916)).abs().max_element() < 1e-5, "{e}");
        let (flat, _) = pairs_to_rgb(&w, &vec![1.0; 95], Use::Emission);
        assert!((flat - e).abs().max_element() < 0.02, "{flat} vs {e}");
    }

    /// A narrow band at 610 nm is red; one at 450 nm is blue.
    #[test]
    fn narrow_bands_have_their_hue() {
        let (red, _) = pairs_to_rgb(&[600.0, 610.0, 620.0], &[0.0, 1.0, 0.0], Use::Emission);
        assert!(red.x > 5.0 * red.y.max(0.0) && red.x > red.z, "{red}");
        let (blue, _) = pairs_to_rgb(&[440.0, 450.0, 460.0], &[0.0, 1.0, 0.0], Use::Emission);
        assert!(blue.z > blue.x && blue.z > blue.y, "{blue}");
    }
}
