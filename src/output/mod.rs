//! Writing and reading images, chosen by extension. Writes go to a
//! temporary file beside the target and are renamed over it only when
//! complete, so an interrupted or failed run never leaves a half-written
//! file in place of a good one.

use crate::error::{Error, Result};
use crate::film::{Film, ToneMap};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

mod exr_file;
pub mod partial;

pub use exr_file::{exr_bytes, read_exr, read_header, Header};

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

/// Checks that `path` can be written, before any rendering time is spent:
/// a known extension, not a directory, not a file the user may not write
/// (a read-only file is never replaced), and a directory where a file can
/// be created (a temporary one is made and removed).
pub fn check_writable(path: &Path) -> Result<Format> {
    let format = Format::from_path(path)?;
    let refuse = |message: String| Error::Io {
        path: path.to_owned(),
        source: std::io::Error::new(std::io::ErrorKind::PermissionDenied, message),
    };
    let dir = existing_parent_dir(path)?;
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_dir() {
            return Err(refuse("is a directory".into()));
        }
        if meta.permissions().readonly() {
            return Err(refuse("the file is read-only; it is not replaced".into()));
        }
    }
    let probe = temporary_path(path);
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) => return Err(refuse(format!("cannot create a file in {}: {e}", dir.display()))),
    }
    Ok(format)
}

/// Whether two paths name the same file (existing or not: a path that does
/// not exist yet is compared by its directory and name).
pub fn same_file(a: &Path, b: &Path) -> bool {
    fn resolve(p: &Path) -> Option<PathBuf> {
        if let Ok(c) = std::fs::canonicalize(p) {
            return Some(c);
        }
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
    }
    match (resolve(a), resolve(b)) {
        (Some(a), Some(b)) => a == b,
        _ => false,
    }
}

/// The directory `path` would be written in, which must exist.
fn existing_parent_dir(path: &Path) -> Result<PathBuf> {
    let dir = parent_dir(path);
    if dir.is_dir() {
        return Ok(dir);
    }
    let why = if dir.exists() { "is not a directory" } else { "does not exist" };
    Err(Error::Io {
        path: path.to_owned(),
        source: std::io::Error::new(std::io::ErrorKind::NotFound, format!("directory {} {why}", dir.display())),
    })
}

fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// What an EXR holds besides the image: header attributes (provenance,
/// a partial's manifest) and more layers (error estimates), each written as
/// channels `NAME.R`, `NAME.G`, `NAME.B`.
#[derive(Clone, Debug, Default)]
pub struct Extras {
    pub attributes: Vec<(String, String)>,
    pub layers: Vec<(String, Film)>,
}

/// Writes `film` to `path` in the format its extension names: EXR holds the
/// linear radiance as 32-bit floats; PNG and PPM hold the tone-mapped view.
pub fn write(path: &Path, film: &Film, tonemap: ToneMap, exposure: f32) -> Result<()> {
    write_with(path, film, tonemap, exposure, &Extras::default())
}

/// [`write`], with `extras` in an EXR (8-bit formats have no room for them).
pub fn write_with(path: &Path, film: &Film, tonemap: ToneMap, exposure: f32, extras: &Extras) -> Result<()> {
    let format = check_writable(path)?;
    atomically(path, |tmp| match format {
        Format::Exr => exr_file::write(tmp, film, extras),
        Format::Png | Format::Ppm => encode_rgb8(tmp, film.width, film.height, film.to_rgb8(tonemap, exposure), format),
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
    existing_parent_dir(path)?;
    atomically(path, |tmp| std::fs::write(tmp, bytes).map_err(|e| Error::Io { path: path.to_owned(), source: e }))
}

/// Temporary files being written, for [`remove_temporaries`].
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes every temporary file this process is writing: for a program
/// that must exit at once (a second Ctrl-C) without leaving any behind.
pub fn remove_temporaries() {
    if let Ok(list) = TEMPORARIES.lock() {
        for p in list.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}

fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    parent_dir(path).join(format!(".{name}.{}.tmp", std::process::id()))
}

/// Runs `write` on a temporary file beside `path`, then renames it over
/// `path`; the temporary file is removed if anything fails.
fn atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let tmp = temporary_path(path);
    if let Ok(mut list) = TEMPORARIES.lock() {
        list.push(tmp.clone());
    }
    let result = write(&tmp)
        .and_then(|()| std::fs::rename(&tmp, path).map_err(|e| Error::Io { path: path.to_owned(), source: e }));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    if let Ok(mut list) = TEMPORARIES.lock() {
        list.retain(|p| p != &tmp);
    }
    result.map_err(|e| match e {
        Error::Encode { message, .. } => Error::Encode { path: path.to_owned(), message },
        other => other,
    })
}

/// An image as the bytes of a Radiance HDR (RGBE) file: 8 bits of
/// mantissa per channel under a shared exponent, so each value within
/// 0.4% of the film's (a compact file for a committed environment map).
pub fn hdr_bytes(film: &Film) -> Result<Vec<u8>> {
    let fail = |message: String| Error::Encode { path: PathBuf::from("(memory)"), message };
    let pixels: Vec<image::Rgb<f32>> =
        film.pixels.iter().map(|c| image::Rgb(c.max(crate::math::Color::ZERO).to_array())).collect();
    let mut bytes = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut bytes)
        .encode(&pixels, film.width as usize, film.height as usize)
        .map_err(|e| fail(e.to_string()))?;
    Ok(bytes)
}

/// PNG by the image crate; PPM as binary P6 (what the course's readers and
/// other renderers take), written here: a header and the bytes.
fn encode_rgb8(tmp: &Path, width: u32, height: u32, rgb: Vec<u8>, format: Format) -> Result<()> {
    let fail = |message: String| Error::Encode { path: tmp.to_owned(), message };
    if rgb.len() != width as usize * height as usize * 3 {
        return Err(fail("image size mismatch".into()));
    }
    match format {
        Format::Ppm => {
            let file = std::fs::File::create(tmp).map_err(|e| Error::Io { path: tmp.to_owned(), source: e })?;
            let mut out = std::io::BufWriter::new(file);
            write!(out, "P6\n{width} {height}\n255\n")
                .and_then(|()| out.write_all(&rgb))
                .and_then(|()| out.flush())
                .map_err(|e| Error::Io { path: tmp.to_owned(), source: e })
        }
        _ => {
            let buf =
                image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| fail("image size mismatch".into()))?;
            buf.save_with_format(tmp, image::ImageFormat::Png).map_err(|e| fail(e.to_string()))
        }
    }
}
