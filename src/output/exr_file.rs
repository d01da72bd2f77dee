//! OpenEXR files: the one module that names the exr crate. Images are
//! float RGB channels plus, where asked, more channel groups and text
//! attributes in the header (provenance, a partial's manifest).

use super::Extras;
use crate::error::{Error, Result};
use crate::film::Film;
use crate::math::Color;
use exr::prelude::*;
use std::path::Path;

/// A channel's samples, as a file holds them.
pub enum Samples {
    F32(Vec<f32>),
    U32(Vec<u32>),
}

/// Prefix of photonmap's own header attributes.
pub const ATTRIBUTE_PREFIX: &str = "photonmap.";

fn encode_error(path: &Path, e: exr::error::Error) -> Error {
    Error::Encode { path: path.to_owned(), message: e.to_string() }
}

fn rgb_channels(prefix: &str, film: &Film) -> [(String, Samples); 3] {
    let channel = |c: usize| film.pixels.iter().map(|p| p.to_array()[c]).collect::<Vec<f32>>();
    let name = |c: &str| if prefix.is_empty() { c.to_string() } else { format!("{prefix}.{c}") };
    [
        (name("R"), Samples::F32(channel(0))),
        (name("G"), Samples::F32(channel(1))),
        (name("B"), Samples::F32(channel(2))),
    ]
}

/// The image, `extras`' layers and attributes.
pub(super) fn write(tmp: &Path, film: &Film, extras: &Extras) -> Result<()> {
    let mut channels: Vec<(String, Samples)> = rgb_channels("", film).into();
    for (name, layer) in &extras.layers {
        channels.extend(rgb_channels(name, layer));
    }
    write_channels(tmp, film.width, film.height, channels, &extras.attributes)
}

/// Any channels (each `width * height` samples, row 0 first) and text
/// attributes (each stored as `photonmap.KEY`), RLE-compressed 64x64
/// tiles (exr's fast lossless default) in increasing order: the tiles are
/// compressed in parallel, and an unspecified order would store them as
/// they finish, so the same pixels would give different files.
pub(super) fn write_channels(
    tmp: &Path,
    width: u32,
    height: u32,
    channels: Vec<(String, Samples)>,
    attributes: &[(String, String)],
) -> Result<()> {
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (name, samples) in channels {
        let samples = match samples {
            Samples::F32(v) => FlatSamples::F32(v),
            Samples::U32(v) => FlatSamples::U32(v),
        };
        list.push(AnyChannel::new(text(&name), samples));
    }
    let mut layer_attributes = LayerAttributes {
        software_name: Some(text(&format!("photonmap {}", env!("CARGO_PKG_VERSION")))),
        ..LayerAttributes::default()
    };
    for (key, value) in attributes {
        layer_attributes.other.insert(text(&format!("{ATTRIBUTE_PREFIX}{key}")), AttributeValue::Text(text(value)));
    }
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    let layer = Layer::new((width as usize, height as usize), layer_attributes, encoding, AnyChannels::sort(list));
    Image::from_layer(layer).write().to_file(tmp).map_err(|e| encode_error(tmp, e))
}

/// An RGB image as the bytes of an EXR file, without photonmap's
/// attributes: a file another program reads (an environment map the
/// Mitsuba export writes beside its scene).
pub fn exr_bytes(film: &Film) -> Result<Vec<u8>> {
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (name, samples) in rgb_channels("", film) {
        let Samples::F32(v) = samples else { unreachable!("colour channels are floats") };
        list.push(AnyChannel::new(text(&name), FlatSamples::F32(v)));
    }
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    let size = (film.width as usize, film.height as usize);
    let layer = Layer::new(size, LayerAttributes::default(), encoding, AnyChannels::sort(list));
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer).write().to_buffered(&mut bytes).map_err(|e| encode_error(Path::new("(memory)"), e))?;
    Ok(bytes.into_inner())
}

/// Text as the header stores it: UTF-8 bytes (exr's own constructor takes
/// only Latin-1 and panics otherwise; a path may hold any character).
fn text(s: &str) -> Text {
    // The format ends strings at a NUL: none may be inside.
    let bytes: Vec<u8> = s.bytes().filter(|&b| b != 0).collect();
    Text::from_slice_unchecked(&bytes)
}

fn string(t: &Text) -> String {
    String::from_utf8_lossy(t.as_slice()).into_owned()
}

/// Reads the first RGB layer of an EXR file as linear radiance.
pub fn read_exr(path: &Path) -> Result<Film> {
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![Color::ZERO; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<Color>), p, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[p.y() * *w + p.x()] = Color::new(r, g, b)
        },
    )
    .map_err(|e| Error::Decode { path: path.to_owned(), message: e.to_string() })?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok(Film { width: size.width() as u32, height: size.height() as u32, pixels })
}

/// What an EXR's header says: its size, channels and text attributes
/// (photonmap's without their prefix, others by their own names).
#[derive(Clone, Debug)]
pub struct Header {
    pub width: u32,
    pub height: u32,
    pub channels: Vec<String>,
    pub attributes: Vec<(String, String)>,
}

impl Header {
    /// A photonmap attribute's value.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.attributes.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
}

/// Reads an EXR's header (not its pixels).
pub fn read_header(path: &Path) -> Result<Header> {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| Error::Decode { path: path.to_owned(), message: e.to_string() })?;
    let header =
        meta.headers.first().ok_or_else(|| Error::Decode { path: path.to_owned(), message: "no image".into() })?;
    let size = header.layer_size;
    let mut attributes = Vec::new();
    if let Some(software) = &header.own_attributes.software_name {
        attributes.push(("software".to_string(), string(software)));
    }
    let mut other: Vec<(String, String)> = header
        .own_attributes
        .other
        .iter()
        .chain(&header.shared_attributes.other)
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => {
                let key = string(k);
                Some((key.strip_prefix(ATTRIBUTE_PREFIX).map(str::to_string).unwrap_or(key), string(t)))
            }
            _ => None,
        })
        .collect();
    other.sort();
    attributes.extend(other);
    Ok(Header {
        width: size.width() as u32,
        height: size.height() as u32,
        channels: header.channels.list.iter().map(|c| string(&c.name)).collect(),
        attributes,
    })
}

/// Reads every channel of the first layer, by name, with the header.
pub(super) fn read_channels(path: &Path) -> Result<(Header, Vec<(String, Samples)>)> {
    let header = read_header(path)?;
    let image = read_first_flat_layer_from_file(path)
        .map_err(|e| Error::Decode { path: path.to_owned(), message: e.to_string() })?;
    let channels = image
        .layer_data
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let samples = match c.sample_data {
                FlatSamples::U32(v) => Samples::U32(v),
                FlatSamples::F32(v) => Samples::F32(v),
                FlatSamples::F16(v) => Samples::F32(v.into_iter().map(|h| h.to_f32()).collect()),
            };
            (string(&c.name), samples)
        })
        .collect();
    Ok((header, channels))
}
