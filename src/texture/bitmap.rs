//! An image as a texture (Mitsuba 3's `bitmap`, src/textures/bitmap.cpp):
//! texel centres at half-integer coordinates of `uv * resolution`, `v`
//! running down the image's rows from its top (row 0 is the file's first
//! row), bilinear interpolation or nearest lookup, and the wrap modes
//! repeat, mirror and clamp. 8- and 16-bit images are sRGB-encoded unless
//! read `raw`, and decoded to linear per texel before interpolation; EXR
//! and Radiance HDR images are linear already.

use crate::math::Color;
use glam::Vec2;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Filter {
    Bilinear,
    Nearest,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

impl Wrap {
    /// A texel index wrapped into `0..n` (n > 0).
    #[inline]
    fn index(self, i: i64, n: i64) -> usize {
        let i = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let i = i.rem_euclid(2 * n);
                if i >= n {
                    2 * n - 1 - i
                } else {
                    i
                }
            }
        };
        i as usize
    }
}

/// Linear texel values, one or three channels, rows from the top.
#[derive(Debug)]
pub struct Bitmap {
    width: u32,
    height: u32,
    /// 1 (grey) or 3 (RGB).
    channels: u32,
    data: Vec<f32>,
    pub filter: Filter,
    pub wrap: Wrap,
    /// The file it was read from and whether read `raw` (what the Mitsuba
    /// export refers to); `None` for an image made in memory.
    pub source: Option<(std::path::PathBuf, bool)>,
}

impl Bitmap {
    /// An image of `channels` (1 or 3) linear values per texel.
    pub fn new(width: u32, height: u32, channels: u32, data: Vec<f32>) -> Result<Self, String> {
        if width == 0 || height == 0 {
            return Err("the image is empty".into());
        }
        if !(channels == 1 || channels == 3) || data.len() != (width * height * channels) as usize {
            return Err("the image's size does not match its data".into());
        }
        if data.iter().any(|v| !v.is_finite()) {
            return Err("the image holds non-finite values".into());
        }
        Ok(Bitmap { width, height, channels, data, filter: Filter::Bilinear, wrap: Wrap::Repeat, source: None })
    }

    /// Reads PNG, JPEG, BMP, PNM, Radiance HDR or OpenEXR, by the file's
    /// extension; `raw` leaves 8- and 16-bit values undecoded.
    pub fn load(path: &Path, raw: bool) -> Result<Self, String> {
        let mut image = Self::decode(path, raw)?;
        image.source = Some((path.to_path_buf(), raw));
        Ok(image)
    }

    fn decode(path: &Path, raw: bool) -> Result<Self, String> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        if ext == "exr" {
            let film = crate::output::read_exr(path).map_err(|e| e.to_string())?;
            let data = film.pixels.iter().flat_map(|c| c.to_array()).collect();
            return Bitmap::new(film.width, film.height, 3, data);
        }
        let meta = std::fs::metadata(path).map_err(|e| format!("cannot open it: {e}"))?;
        if !meta.is_file() {
            return Err("it is not a regular file".into());
        }
        let image = image::ImageReader::open(path)
            .map_err(|e| format!("cannot open it: {e}"))?
            .with_guessed_format()
            .map_err(|e| format!("cannot read it: {e}"))?
            .decode()
            .map_err(|e| format!("cannot decode it: {e}"))?;
        let (width, height) = (image.width(), image.height());
        let grey = !image.color().has_color();
        let linear = matches!(image, image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_));
        let decode = |v: f32| if raw || linear { v } else { srgb_to_linear(v) };
        let data: Vec<f32> = if grey {
            image.to_luma32f().into_raw().into_iter().map(decode).collect()
        } else {
            image.to_rgb32f().into_raw().into_iter().map(decode).collect()
        };
        Bitmap::new(width, height, if grey { 1 } else { 3 }, data)
    }

    pub fn filter_name(&self) -> &'static str {
        match self.filter {
            Filter::Bilinear => "bilinear",
            Filter::Nearest => "nearest",
        }
    }

    pub fn wrap_name(&self) -> &'static str {
        match self.wrap {
            Wrap::Repeat => "repeat",
            Wrap::Mirror => "mirror",
            Wrap::Clamp => "clamp",
        }
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> Color {
        let x = self.wrap.index(x, self.width as i64);
        let y = self.wrap.index(y, self.height as i64);
        let i = (y * self.width as usize + x) * self.channels as usize;
        if self.channels == 1 {
            Color::splat(self.data[i])
        } else {
            Color::new(self.data[i], self.data[i + 1], self.data[i + 2])
        }
    }

    /// The value at texture coordinates `uv`.
    pub fn eval(&self, uv: Vec2) -> Color {
        let res = Vec2::new(self.width as f32, self.height as f32);
        if !uv.is_finite() {
            return Color::ZERO;
        }
        match self.filter {
            Filter::Nearest => {
                let p = (uv * res).floor();
                self.texel(p.x as i64, p.y as i64)
            }
            Filter::Bilinear => {
                let p = uv * res - 0.5;
                let i = p.floor();
                let w1 = p - i;
                let w0 = Vec2::ONE - w1;
                let (x, y) = (i.x as i64, i.y as i64);
                let top = self.texel(x, y) * w0.x + self.texel(x + 1, y) * w1.x;
                let bottom = self.texel(x, y + 1) * w0.x + self.texel(x + 1, y + 1) * w1.x;
                top * w0.y + bottom * w1.y
            }
        }
    }

    /// The derivatives of the bilinear lookup's luminance by texel
    /// coordinates x and y at `uv` (zero for nearest lookup).
    pub fn gradient(&self, uv: Vec2) -> Vec2 {
        if self.filter == Filter::Nearest || !uv.is_finite() {
            return Vec2::ZERO;
        }
        let p = uv * self.resolution() - 0.5;
        let i = p.floor();
        let w1 = p - i;
        let w0 = Vec2::ONE - w1;
        let (x, y) = (i.x as i64, i.y as i64);
        let f = |dx, dy| crate::texture::luminance_or_grey(self.texel(x + dx, y + dy), self.channels == 1);
        let (f00, f10, f01, f11) = (f(0, 0), f(1, 0), f(0, 1), f(1, 1));
        Vec2::new(w0.y * (f10 - f00) + w1.y * (f11 - f01), w0.x * (f01 - f00) + w1.x * (f11 - f10))
    }

    /// Width and height.
    pub fn resolution(&self) -> Vec2 {
        Vec2::new(self.width as f32, self.height as f32)
    }

    /// Whether the image is grey (one channel).
    pub fn is_grey(&self) -> bool {
        self.channels == 1
    }

    /// The mean of the texels.
    pub fn mean(&self) -> Color {
        let n = (self.width * self.height) as f64;
        let mut sum = [0.0f64; 3];
        for px in self.data.chunks_exact(self.channels as usize) {
            for (c, s) in sum.iter_mut().enumerate() {
                *s += px[c.min(px.len() - 1)] as f64;
            }
        }
        Color::new((sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32)
    }

    /// The smallest value of any channel.
    pub fn min(&self) -> f32 {
        self.data.iter().copied().fold(f32::INFINITY, f32::min)
    }

    /// The largest value of any channel.
    pub fn max(&self) -> f32 {
        self.data.iter().copied().fold(0.0, f32::max)
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Bitmap {
        // 4 x 2, grey: row 0 is 0 1 2 3, row 1 is 10 11 12 13.
        let data = vec![0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0];
        Bitmap::new(4, 2, 1, data).unwrap()
    }

    #[test]
    fn texel_centres_return_their_texels() {
        let b = ramp();
        for y in 0..2 {
            for x in 0..4 {
                let uv = Vec2::new((x as f32 + 0.5) / 4.0, (y as f32 + 0.5) / 2.0);
                let want = (10 * y + x) as f32;
                assert!((b.eval(uv).x - want).abs() < 1e-5, "{uv} {}", b.eval(uv).x);
            }
        }
    }

    #[test]
    fn bilinear_interpolates_between_centres_and_wraps() {
        let mut b = ramp();
        // Halfway between texels (1, 0) and (2, 0).
        assert!((b.eval(Vec2::new(0.5, 0.25)).x - 1.5).abs() < 1e-5);
        // Left of the first centre: repeat blends with the last column.
        let v = b.eval(Vec2::new(0.0, 0.25)).x;
        assert!((v - 1.5).abs() < 1e-5, "{v}");
        b.wrap = Wrap::Clamp;
        assert!((b.eval(Vec2::new(0.0, 0.25)).x - 0.0).abs() < 1e-5);
        b.wrap = Wrap::Mirror;
        assert!((b.eval(Vec2::new(-0.01, 0.25)).x - 0.0).abs() < 1e-5);
        b.filter = Filter::Nearest;
        b.wrap = Wrap::Repeat;
        assert_eq!(b.eval(Vec2::new(1.1, 0.7)).x, 10.0);
        b.wrap = Wrap::Mirror;
        // Texel -1 mirrors onto texel 0, texel 4 onto texel 3.
        assert_eq!(b.eval(Vec2::new(-0.1, 0.1)).x, 0.0);
        assert_eq!(b.eval(Vec2::new(1.1, 0.1)).x, 3.0);
    }

    /// The gradient of the bilinear lookup is its slope between texel
    /// centres, per texel: the ramp rises by 1 per texel across x and by
    /// 10 from row to row; nearest lookup is flat.
    #[test]
    fn the_gradient_is_the_ramps_slope() {
        let mut b = ramp();
        let g = b.gradient(Vec2::new(0.45, 0.25));
        assert!((g - Vec2::new(1.0, 10.0)).length() < 1e-4, "{g}");
        b.filter = Filter::Nearest;
        assert_eq!(b.gradient(Vec2::new(0.45, 0.25)), Vec2::ZERO);
    }

    #[test]
    fn srgb_decoding_matches_the_standard() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
    }
}
