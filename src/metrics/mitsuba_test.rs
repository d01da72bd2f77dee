//! Mitsuba 3's render-test acceptance, applied to any image with a
//! reference and the reference's per-pixel variance: the test that judges
//! the renders of Mitsuba's own test scenes (`z_test` and `test_render` in
//! src/render/tests/test_renders.py of mitsuba-renderer/mitsuba3).
//!
//! * The three images are converted from linear sRGB to CIE XYZ with the
//!   matrix of Mitsuba's `Bitmap::convert` (src/core/bitmap.cpp), the
//!   variance too (Mitsuba converts it as it converts a colour).
//! * The reference variance is floored at 1e-4.
//! * The sample budget is 2,000,000 samples over the image: spp =
//!   2,000,000 / pixels, in integers.
//! * Each pixel's channel has z = |image − reference|·√(spp / variance)
//!   and passes when its two-sided p-value erfc(z/√2) exceeds the Šidák
//!   level 1 − (1 − 0.01)^(1/pixels).
//! * The image is accepted when the passing channels, divided by three,
//!   are at least 99.75% of the pixels.
//!
//! Where this differs from Mitsuba's code, and why:
//! * Everything is computed in double precision, p by Cody's erfc
//!   (`super::erfc`), as the Python version of this test (ztest.py) does.
//!   Mitsuba computes p = 2·(1 − cdf(z)) in single precision, where p near
//!   0 is a multiple of 2⁻²³ ≈ 1.19e-7: with a correctly rounded erf a
//!   channel passes there only when its exact p exceeds about 8.9e-8
//!   (1.5·2⁻²⁴). For images of more than about 112,000 pixels, whose level
//!   is below that, Mitsuba's threshold on z is then about 5.35 instead of
//!   the level's (5.48 at 480x480); at 48x48 the level, 4.4e-6, is 37 such
//!   steps and the thresholds differ by under 0.01 in z.
//! * An image holding a non-finite value is rejected, whatever the share
//!   of passing pixels (Mitsuba's test only fails that pixel's channels, as
//!   a NaN's p-value is NaN): a render that produced a NaN is broken.
//! * A reference or variance holding a non-finite value, or an image of
//!   more than 2,000,000 pixels (a budget of 0 spp makes every z 0), is
//!   refused as unusable instead of scored.

use super::erfc::two_sided_p;
use crate::film::{Film, ToneMap};
use crate::math::Color;

/// Samples the test spreads over the image (Mitsuba's `sample_budget`).
pub const SAMPLE_BUDGET: u64 = 2_000_000;
/// The family-wise significance level (Mitsuba's `significance_level`).
pub const SIGNIFICANCE: f64 = 0.01;
/// The floor under the reference's variance.
pub const VARIANCE_FLOOR: f64 = 1e-4;
/// The least share of pixels that must pass.
pub const PASSING_SHARE: f64 = 0.9975;

/// Linear sRGB to CIE XYZ, rows X, Y, Z: the coefficients of Mitsuba's
/// `Bitmap::convert` (and of its `srgb_to_xyz`).
const RGB_TO_XYZ: [[f64; 3]; 3] =
    [[0.412453, 0.357580, 0.180423], [0.212671, 0.715160, 0.072169], [0.019334, 0.119193, 0.950227]];

fn xyz(c: Color) -> [f64; 3] {
    let rgb = [c.x as f64, c.y as f64, c.z as f64];
    RGB_TO_XYZ.map(|row| row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2])
}

/// The sample budget per pixel for an image of `pixels` pixels.
pub fn spp_budget(pixels: u64) -> u64 {
    SAMPLE_BUDGET / pixels.max(1)
}

/// The Šidák-corrected level of each pixel's test, 1 − (1 − 0.01)^(1/pixels),
/// computed as −expm1(ln(0.99)/pixels) so that no digit is lost to the
/// subtraction from 1.
pub fn sidak_level(pixels: u64) -> f64 {
    -((-SIGNIFICANCE).ln_1p() / pixels.max(1) as f64).exp_m1()
}

/// The outcome of the test.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the test's budget.
    pub spp: u64,
    /// The level each channel's p-value must exceed.
    pub level: f64,
    /// Pixel channels (three per pixel) whose p-value exceeds the level.
    pub passing_channels: u64,
    /// `passing_channels` / (3 · pixels): what must reach 99.75%.
    pub fraction_passing: f64,
    /// The smallest p-value of any channel (a non-finite image value
    /// counts as 0).
    pub min_p: f64,
    /// Per pixel, row 0 first: whether any of its channels fails.
    pub failing: Vec<bool>,
    /// Non-finite values in the image (RGB channels as the file holds them;
    /// one makes all three XYZ channels of its pixel fail).
    pub non_finite: u64,
    /// |mean(image) − mean(reference)| / mean(reference), over every pixel
    /// and XYZ channel (`mean_rel_err` of the Python version of this test,
    /// tools' ztest.py); `None` where the reference's mean is not positive
    /// or the image holds a non-finite value.
    pub mean_relative_error: Option<f64>,
    pub accepted: bool,
}

impl Verdict {
    pub fn pixels(&self) -> u64 {
        self.failing.len() as u64
    }

    pub fn failing_pixels(&self) -> u64 {
        self.failing.iter().filter(|&&f| f).count() as u64
    }

    /// A picture of the failing pixels, 8-bit RGB at the test's size:
    /// failing pixels pure red, the others the image's display view at a
    /// third of its brightness (the scene stays recognisable under the
    /// marks, as in the error image Mitsuba's test writes).
    pub fn fail_map_rgb8(&self, image: &Film) -> Vec<u8> {
        let view = image.to_rgb8(ToneMap::Display, 1.0);
        view.chunks_exact(3)
            .zip(&self.failing)
            .flat_map(|(px, &fail)| if fail { [255, 0, 0] } else { [px[0] / 3, px[1] / 3, px[2] / 3] })
            .collect()
    }
}

/// One of the test's three inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    Image,
    Reference,
    Variance,
}

impl std::fmt::Display for Input {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            Input::Image => "image",
            Input::Reference => "reference",
            Input::Variance => "variance image",
        })
    }
}

/// Why the test cannot be run on three images.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Unusable {
    #[error("the {which} is {w}x{h} but the reference is {ref_w}x{ref_h}: the test compares pixel by pixel")]
    Size { which: Input, w: u32, h: u32, ref_w: u32, ref_h: u32 },
    #[error("the reference has no pixels")]
    Empty,
    #[error(
        "the reference has {pixels} pixels: the test's budget of {SAMPLE_BUDGET} samples gives 0 per pixel, so every pixel would pass"
    )]
    TooLarge { pixels: u64 },
    #[error("the {which} holds {count} non-finite values (NaN or infinite; the first at column {col}, row {row}): the test needs a finite {which}")]
    NonFinite { which: Input, count: u64, col: u32, row: u32 },
}

/// The non-finite values of `film`: their count and the first one's place.
fn non_finite(film: &Film) -> Option<(u64, u32, u32)> {
    let mut first = None;
    let mut count = 0;
    for (i, c) in film.pixels.iter().enumerate() {
        let bad = c.to_array().iter().filter(|v| !v.is_finite()).count() as u64;
        if bad > 0 && first.is_none() {
            first = Some(i as u32);
        }
        count += bad;
    }
    first.map(|i| (count, i % film.width.max(1), i / film.width.max(1)))
}

/// Mitsuba's acceptance test of `image` against `reference` and its
/// per-pixel `variance` (all three linear RGB, the same size).
pub fn mitsuba_test(image: &Film, reference: &Film, variance: &Film) -> Result<Verdict, Unusable> {
    let (w, h) = (reference.width, reference.height);
    for (which, film) in [(Input::Image, image), (Input::Variance, variance)] {
        if (film.width, film.height) != (w, h) {
            return Err(Unusable::Size { which, w: film.width, h: film.height, ref_w: w, ref_h: h });
        }
    }
    let pixels = w as u64 * h as u64;
    if pixels == 0 {
        return Err(Unusable::Empty);
    }
    if pixels > SAMPLE_BUDGET {
        return Err(Unusable::TooLarge { pixels });
    }
    for (which, film) in [(Input::Reference, reference), (Input::Variance, variance)] {
        if let Some((count, col, row)) = non_finite(film) {
            return Err(Unusable::NonFinite { which, count, col, row });
        }
    }
    let spp = spp_budget(pixels);
    let level = sidak_level(pixels);
    let mut passing_channels = 0u64;
    let mut min_p = 1.0f64;
    let non_finite_values = non_finite(image).map_or(0, |(count, _, _)| count);
    let mut failing = Vec::with_capacity(pixels as usize);
    let (mut sum_image, mut sum_reference) = (0.0f64, 0.0f64);
    for ((x, r), v) in image.pixels.iter().zip(&reference.pixels).zip(&variance.pixels) {
        let (x, r, v) = (xyz(*x), xyz(*r), xyz(*v));
        let mut fail = false;
        for c in 0..3 {
            let p = if x[c].is_finite() {
                two_sided_p((x[c] - r[c]).abs() * (spp as f64 / v[c].max(VARIANCE_FLOOR)).sqrt())
            } else {
                0.0
            };
            min_p = min_p.min(p);
            if p > level {
                passing_channels += 1;
            } else {
                fail = true;
            }
            sum_image += x[c];
            sum_reference += r[c];
        }
        failing.push(fail);
    }
    let mean_relative_error =
        (sum_reference > 0.0 && non_finite_values == 0).then(|| (sum_image - sum_reference).abs() / sum_reference);
    // Mitsuba's criterion as it is written, count / 3 >= 0.9975 * pixels.
    let accepted = passing_channels as f64 / 3.0 >= PASSING_SHARE * pixels as f64 && non_finite_values == 0;
    Ok(Verdict {
        width: w,
        height: h,
        spp,
        level,
        passing_channels,
        fraction_passing: passing_channels as f64 / (3 * pixels) as f64,
        min_p,
        failing,
        non_finite: non_finite_values,
        mean_relative_error,
        accepted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(w: u32, h: u32, f: impl Fn(u32, u32) -> Color) -> Film {
        Film { width: w, height: h, pixels: (0..w * h).map(|i| f(i % w, i / w)).collect() }
    }

    #[test]
    fn the_budget_and_the_level_are_mitsubas() {
        assert_eq!(spp_budget(48 * 48), 868);
        assert_eq!(spp_budget(480 * 480), 8);
        // 1 - 0.99^(1/2304), computed directly in 50 digits.
        let want = 4.362_115_422_318_35e-6;
        assert!((sidak_level(48 * 48) / want - 1.0).abs() < 1e-9, "{}", sidak_level(2304));
        assert!((sidak_level(1) - 0.01).abs() < 1e-15);
    }

    /// One channel off by a known z: its p-value is the known one, it fails
    /// where the level is above it, and one failing pixel of 400 is within
    /// the 0.25% allowed while two are not.
    #[test]
    fn known_offsets_give_known_p_values_and_the_share_decides() {
        let reference = film(20, 20, |_, _| Color::splat(0.5));
        // A zero variance is floored at 1e-4: z = d · sqrt(5000 / 1e-4).
        let variance = film(20, 20, |_, _| Color::ZERO);
        let spp = spp_budget(400) as f64;
        assert_eq!(spp, 5000.0);
        // Grey offsets: in XYZ, Y = the grey value itself (its row sums to 1).
        let off = 0.5 + (6.0 * (1e-4f64 / spp).sqrt()) as f32;
        // The offset as the f32 image holds it (the subtraction is exact).
        let d = (off - 0.5) as f64;
        let one = film(20, 20, |x, y| Color::splat(if (x, y) == (3, 4) { off } else { 0.5 }));
        let v = mitsuba_test(&one, &reference, &variance).unwrap();
        assert!((v.level / (1.0 - 0.99f64.powf(1.0 / 400.0)) - 1.0).abs() < 1e-9, "{}", v.level);
        // X's and Z's rows sum to 0.950456 and 1.088754: z scales with
        // them, and Z's (z near 6.5) has the smallest p-value.
        let z = 1.088754 * d * (spp / 1e-4).sqrt();
        assert!((v.min_p / two_sided_p(z) - 1.0).abs() < 1e-9, "{} against {}", v.min_p, two_sided_p(z));
        assert_eq!(v.failing_pixels(), 1);
        assert_eq!(v.passing_channels, 3 * 400 - 3);
        assert!(v.accepted, "one pixel of 400 may fail");
        let two = film(20, 20, |x, y| Color::splat(if y == 4 && x < 2 { off } else { 0.5 }));
        let v = mitsuba_test(&two, &reference, &variance).unwrap();
        assert_eq!(v.failing_pixels(), 2);
        assert!(!v.accepted, "two of 400 is over 0.25%");
        assert!(v.failing[4 * 20] && v.failing[4 * 20 + 1] && !v.failing[0]);
    }

    #[test]
    fn a_nan_rejects_and_broken_inputs_are_refused() {
        let reference = film(4, 4, |_, _| Color::splat(0.5));
        let variance = film(4, 4, |_, _| Color::splat(0.1));
        let nan = film(4, 4, |x, _| Color::new(if x == 1 { f32::NAN } else { 0.5 }, 0.5, 0.5));
        let v = mitsuba_test(&nan, &reference, &variance).unwrap();
        assert!(!v.accepted && v.non_finite == 4 && v.min_p == 0.0 && v.mean_relative_error.is_none());
        assert!(mitsuba_test(&reference, &reference, &variance).unwrap().accepted);
        let mut bad = variance.clone();
        bad.pixels[6] = Color::new(0.1, f32::INFINITY, 0.1);
        assert_eq!(
            mitsuba_test(&reference, &reference, &bad),
            Err(Unusable::NonFinite { which: Input::Variance, count: 1, col: 2, row: 1 })
        );
        let small = film(4, 3, |_, _| Color::ONE);
        assert!(matches!(mitsuba_test(&small, &reference, &variance), Err(Unusable::Size { which: Input::Image, .. })));
        assert!(matches!(mitsuba_test(&reference, &reference, &small), Err(Unusable::Size { .. })));
        let zero = film(4, 4, |_, _| Color::ZERO);
        assert_eq!(mitsuba_test(&zero, &zero, &variance).unwrap().mean_relative_error, None);
    }
}
