//! The film: linear radiance per pixel, row 0 at the top; and the course's
//! ways of turning it into 8-bit values. The exact sums of a progressive
//! render's passes are films too ([`accumulation`]).

pub mod accumulation;

use crate::math::Color;

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Color>,
}

/// How radiance becomes an 8-bit value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// A display transform: the image's exposure set so that its
    /// log-average luminance (over pixels that see something) becomes
    /// middle grey 0.18 (Reinhard et al. 2002), times `exposure`, then the
    /// sRGB curve; what passes white clips. A bright light in view does not
    /// darken the rest.
    #[default]
    Display,
    /// The course's mapping (TNCG15 lecture 6): v * 255.99 / i_max, i_max
    /// the largest channel value in the image.
    Linear,
    /// sqrt(v) * 255.99 / sqrt(i_max): for scenes with bright spots.
    Sqrt,
    /// v * 255.99 clamped: 1.0 is white (the Whitted course's colours).
    Clamp,
}

impl ToneMap {
    pub const ALL: [ToneMap; 4] = [ToneMap::Display, ToneMap::Linear, ToneMap::Sqrt, ToneMap::Clamp];

    /// Its name on command lines.
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Display => "display",
            ToneMap::Linear => "linear",
            ToneMap::Sqrt => "sqrt",
            ToneMap::Clamp => "clamp",
        }
    }

    /// What it does, for a command's help.
    pub fn description(self) -> &'static str {
        match self {
            ToneMap::Display => "Exposure from the image (its log-average luminance to middle grey), then sRGB.",
            ToneMap::Linear => "The course's: v * 255.99 / i_max, i_max the largest channel value.",
            ToneMap::Sqrt => "The course's square-root variant: sqrt(v) * 255.99 / sqrt(i_max).",
            ToneMap::Clamp => "v * 255.99 clamped: 1.0 is white (the Whitted course's colours).",
        }
    }
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        Film { width, height, pixels: vec![Color::ZERO; width as usize * height as usize] }
    }

    pub fn get(&self, col: u32, row: u32) -> Color {
        self.pixels[row as usize * self.width as usize + col as usize]
    }

    /// Mean of all pixels and channels.
    pub fn mean(&self) -> f64 {
        self.pixels.iter().map(|c| (c.x + c.y + c.z) as f64).sum::<f64>() / (3 * self.pixels.len()).max(1) as f64
    }

    /// The factor [`ToneMap::Display`] scales radiance by before the sRGB
    /// curve: 0.18 over the log-average luminance of the pixels brighter
    /// than a thousandth of the mean (a black background does not count).
    pub fn display_scale(&self) -> f32 {
        let luminance = |c: &Color| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        let mean =
            self.pixels.iter().map(|c| luminance(c).max(0.0) as f64).sum::<f64>() / self.pixels.len().max(1) as f64;
        let floor = 1e-3 * mean;
        let (mut sum, mut n) = (0.0f64, 0usize);
        for c in &self.pixels {
            let l = luminance(c) as f64;
            if l > floor && l.is_finite() {
                sum += l.ln();
                n += 1;
            }
        }
        if n == 0 {
            return 1.0;
        }
        let scale = 0.18 / (sum / n as f64).exp();
        if scale.is_finite() && scale > 0.0 {
            scale as f32
        } else {
            1.0
        }
    }

    /// 8-bit RGB, row-major. [`ToneMap::Display`]: radiance times the
    /// image's display scale and `exposure`, through the sRGB curve. The
    /// course's mappings: each value against the image's largest value
    /// i_max (which becomes 255.99), times `exposure`, truncated. Values are
    /// clamped to [0, 255].
    pub fn to_rgb8(&self, tonemap: ToneMap, exposure: f32) -> Vec<u8> {
        if tonemap == ToneMap::Display {
            let scale = self.display_scale() * exposure.max(0.0);
            return self
                .pixels
                .iter()
                .flat_map(|c| c.to_array())
                .map(|v| (255.0 * srgb((v * scale).clamp(0.0, 1.0)) + 0.5) as u8)
                .collect();
        }
        let curve = |v: f32| match tonemap {
            ToneMap::Linear => v.max(0.0),
            ToneMap::Sqrt => v.max(0.0).sqrt(),
            ToneMap::Clamp | ToneMap::Display => v.max(0.0),
        };
        let i_max = match tonemap {
            ToneMap::Clamp => 1.0,
            _ => self.pixels.iter().fold(0.0f32, |m, c| m.max(c.max_element())),
        };
        let scale = if i_max > 0.0 { 255.99 / curve(i_max) * exposure.max(0.0) } else { 0.0 };
        self.pixels.iter().flat_map(|c| c.to_array()).map(|v| (curve(v) * scale).clamp(0.0, 255.0) as u8).collect()
    }
}

/// The sRGB transfer curve (IEC 61966-2-1) for a linear value in [0, 1].
pub fn srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(values: &[f32]) -> Film {
        Film { width: values.len() as u32, height: 1, pixels: values.iter().map(|&v| Color::splat(v)).collect() }
    }

    #[test]
    fn linear_tonemap_maps_the_maximum_to_255_and_truncates() {
        let f = film(&[0.0, 1.0, 2.5, 10.0]);
        let px: Vec<u8> = f.to_rgb8(ToneMap::Linear, 1.0).chunks(3).map(|c| c[0]).collect();
        assert_eq!(px, vec![0, 25, 63, 255]);
        // sqrt: sqrt(2.5 / 10) = 0.5 -> 127.995 -> 127
        let px: Vec<u8> = f.to_rgb8(ToneMap::Sqrt, 1.0).chunks(3).map(|c| c[0]).collect();
        assert_eq!(px, vec![0, 80, 127, 255]);
    }

    /// The display transform puts the log-average at middle grey, whatever
    /// one bright pixel does, and ignores a black background.
    #[test]
    fn the_display_transform_exposes_for_the_image_not_its_brightest_pixel() {
        let mut values = vec![0.05f32; 99];
        values.push(1000.0);
        values.extend([0.0; 50]);
        let f = film(&values);
        let scale = f.display_scale();
        // The log-average of 99 at 0.05 and one at 1000 (the zeros do not count).
        let want = 0.18 / ((99.0 * 0.05f64.ln() + 1000f64.ln()) / 100.0).exp();
        assert!((scale as f64 / want - 1.0).abs() < 1e-4, "{scale} vs {want}");
        let px = f.to_rgb8(ToneMap::Display, 1.0);
        assert!(px[0] > 60 && px[0] < 190, "{}", px[0]);
        assert_eq!(px[99 * 3], 255);
        assert_eq!(px[149 * 3], 0);
        assert!((srgb(0.5) - 0.7354).abs() < 1e-3 && (srgb(1.0) - 1.0).abs() < 1e-6 && srgb(0.0) == 0.0);
    }

    #[test]
    fn exposure_brightens_and_clamps() {
        let f = film(&[1.0, 2.5, 10.0]);
        let px: Vec<u8> = f.to_rgb8(ToneMap::Linear, 4.0).chunks(3).map(|c| c[0]).collect();
        assert_eq!(px, vec![102, 255, 255]);
        // A black image stays black rather than dividing by zero.
        assert!(film(&[0.0, 0.0]).to_rgb8(ToneMap::Linear, 2.0).iter().all(|&v| v == 0));
    }
}
