//! The film: linear radiance per pixel, row 0 at the top; and the course's
//! ways of turning it into 8-bit values.

use crate::math::Color;

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Color>,
}

/// How radiance becomes an 8-bit value (TNCG15 lecture 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// v * 255.99 / i_max, i_max the largest channel value in the image.
    #[default]
    Linear,
    /// sqrt(v) * 255.99 / sqrt(i_max): for scenes with bright spots.
    Sqrt,
    /// v * 255.99 clamped: 1.0 is white (the Whitted course's colours).
    Clamp,
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

    /// 8-bit RGB, row-major: each value mapped by `tonemap` against the
    /// image's largest value i_max (so i_max becomes 255.99, as the course
    /// does), multiplied by `exposure`, truncated and clamped to [0, 255].
    /// An exposure above 1 brightens a room that one bright light would
    /// otherwise leave dark; what passes 255 clips.
    pub fn to_rgb8(&self, tonemap: ToneMap, exposure: f32) -> Vec<u8> {
        let curve = |v: f32| match tonemap {
            ToneMap::Linear => v.max(0.0),
            ToneMap::Sqrt => v.max(0.0).sqrt(),
            ToneMap::Clamp => v.max(0.0),
        };
        let i_max = match tonemap {
            ToneMap::Clamp => 1.0,
            _ => self.pixels.iter().fold(0.0f32, |m, c| m.max(c.max_element())),
        };
        let scale = if i_max > 0.0 { 255.99 / curve(i_max) * exposure.max(0.0) } else { 0.0 };
        self.pixels.iter().flat_map(|c| c.to_array()).map(|v| (curve(v) * scale).clamp(0.0, 255.0) as u8).collect()
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

    #[test]
    fn exposure_brightens_and_clamps() {
        let f = film(&[1.0, 2.5, 10.0]);
        let px: Vec<u8> = f.to_rgb8(ToneMap::Linear, 4.0).chunks(3).map(|c| c[0]).collect();
        assert_eq!(px, vec![102, 255, 255]);
        // A black image stays black rather than dividing by zero.
        assert!(film(&[0.0, 0.0]).to_rgb8(ToneMap::Linear, 2.0).iter().all(|&v| v == 0));
    }
}
