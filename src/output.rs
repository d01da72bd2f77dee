//! Writing and reading images, chosen by extension. Writes go to a
//! temporary file beside the target and are renamed over it only when
//! complete, so an interrupted or failed run never leaves a half-written
//! file in place of a good one.

use crate::error::{Error, Result};
use crate::film::{Film, ToneMap};
use crate::math::Color;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Exr,
    Png,
    Ppm,
}

impl Format {
    pub fn from_path(path: &Path) -> Result<Format> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("exr") => Ok(Format::Exr),
            Some("png") => Ok(Format::Png),
            Some("ppm") => Ok(Format::Ppm),
            _ => Err(Error::UnknownExtension { path: path.to_owned() }),
        }
    }
}

/// Checks that `path` can be written (known extension, existing directory)
/// before any rendering time is spent.
pub fn check_writable(path: &Path) -> Result<Format> {
    let format = Format::from_path(path)?;
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(Error::Io {
            path: path.to_owned(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("directory {} does not exist", dir.display()),
            ),
        });
    }
    Ok(format)
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// Writes `film` to `path` in the format its extension names: EXR holds the
/// linear radiance as 32-bit floats; PNG and PPM hold the tone-mapped view.
pub fn write(path: &Path, film: &Film, tonemap: ToneMap, exposure: f32) -> Result<()> {
    let format = check_writable(path)?;
    atomically(path, |tmp| match format {
        Format::Exr => write_exr(tmp, film),
        Format::Png | Format::Ppm => write_rgb8(tmp, film, tonemap, exposure, format),
    })
}

/// Writes 8-bit RGB pixels (row-major, row 0 at the top) as PNG or PPM, by
/// `path`'s extension.
pub fn write_rgb8_image(path: &Path, width: u32, height: u32, rgb: Vec<u8>) -> Result<()> {
    let format = check_writable(path)?;
    if format == Format::Exr {
        return Err(Error::Invalid(format!("{}: an 8-bit picture is written as .png or .ppm", path.display())));
    }
    atomically(path, |tmp| encode_rgb8(tmp, width, height, rgb, format))
}

/// Writes `bytes` to `path` atomically (any file: the exporter's XML and
/// meshes).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(Error::Io {
            path: path.to_owned(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("directory {} does not exist", dir.display()),
            ),
        });
    }
    atomically(path, |tmp| std::fs::write(tmp, bytes).map_err(|e| Error::Io { path: path.to_owned(), source: e }))
}

/// Runs `write` on a temporary file beside `path`, then renames it over
/// `path`; the temporary file is removed if anything fails.
fn atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = parent_dir(path).join(format!(".{name}.{}.tmp", std::process::id()));
    let result = write(&tmp)
        .and_then(|()| std::fs::rename(&tmp, path).map_err(|e| Error::Io { path: path.to_owned(), source: e }));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|e| match e {
        Error::Encode { message, .. } => Error::Encode { path: path.to_owned(), message },
        other => other,
    })
}

/// Float RGB, RLE-compressed 64x64 tiles (exr's fast lossless default),
/// written in increasing line order: the tiles are compressed in parallel,
/// and an unspecified order would store them as they finish, so the same
/// pixels would give different files from run to run.
fn write_exr(tmp: &Path, film: &Film) -> Result<()> {
    use exr::prelude::*;
    let w = film.width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let c = film.pixels[y * w + x];
        (c.x, c.y, c.z)
    });
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    Image::from_encoded_channels((w, film.height as usize), encoding, channels)
        .write()
        .to_file(tmp)
        .map_err(|e| crate::error::Error::Encode { path: tmp.to_owned(), message: e.to_string() })
}

fn write_rgb8(tmp: &Path, film: &Film, tonemap: ToneMap, exposure: f32, format: Format) -> Result<()> {
    encode_rgb8(tmp, film.width, film.height, film.to_rgb8(tonemap, exposure), format)
}

fn encode_rgb8(tmp: &Path, width: u32, height: u32, rgb: Vec<u8>, format: Format) -> Result<()> {
    let buf = image::RgbImage::from_raw(width, height, rgb)
        .ok_or_else(|| Error::Encode { path: tmp.to_owned(), message: "image size mismatch".into() })?;
    let fmt = if format == Format::Png { image::ImageFormat::Png } else { image::ImageFormat::Pnm };
    buf.save_with_format(tmp, fmt).map_err(|e| Error::Encode { path: tmp.to_owned(), message: e.to_string() })
}

/// Reads the first RGB layer of an EXR file as linear radiance.
pub fn read_exr(path: &Path) -> Result<Film> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![Color::ZERO; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<Color>), p, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[p.y() * *w + p.x()] = Color::new(r, g, b)
        },
    )
    .map_err(|e| crate::error::Error::Decode { path: path.to_owned(), message: e.to_string() })?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok(Film { width: size.width() as u32, height: size.height() as u32, pixels })
}
