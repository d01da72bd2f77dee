//! Mitsuba's `serialized` meshes, versions 3 and 4: the layout as Mitsuba 3
//! documents and reads it (src/shapes/serialized.cpp, "Format description"
//! and `load_legacy`; Mitsuba 0.6's documentation has the same tables).
//!
//! Little endian throughout. A file is a sequence of shapes, each an
//! uncompressed header (`u16` 0x041C, `u16` version) and then one zlib
//! stream holding
//!
//! - `u32` flags: 0x0001 vertex normals, 0x0002 texture coordinates,
//!   0x0008 vertex colours, 0x0010 face normals (render faceted), 0x1000
//!   single and 0x2000 double precision;
//! - version 4 only: the shape's name, UTF-8 up to a NUL byte;
//! - `u64` vertex count V, `u64` triangle count F;
//! - V positions (3 floats), then if flagged V normals (3), V texture
//!   coordinates (2), V colours (3), floats of the flagged precision;
//! - F triangles, 3 `u32` vertex indices each.
//!
//! The file ends with a dictionary: one offset per shape (the first is 0),
//! `u32` in version 3 and `u64` in version 4, then the `u32` shape count.
//!
//! Errors name the file, the shape and the byte: a byte of the file, or a
//! byte of the shape's decompressed stream. No count is trusted before it is
//! checked against the bytes that would hold it, so a corrupt count cannot
//! ask for more memory than the stream's own length.

use super::ply::PlyMesh;
use flate2::read::ZlibDecoder;
use glam::{Vec2, Vec3};
use std::io::Read;
use std::path::Path;

/// One shape of a serialized file.
#[derive(Debug, Clone, Default)]
pub struct SerializedMesh {
    /// The shape's name (version 4; empty in version 3).
    pub name: String,
    /// The file asks for face normals (flag 0x0010).
    pub face_normals: bool,
    pub mesh: PlyMesh,
}

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;
/// The flags this reader knows (0x0004, tangents, was never written).
const KNOWN: u32 = HAS_NORMALS | HAS_UVS | 0x0004 | HAS_COLORS | FACE_NORMALS | SINGLE | DOUBLE;
/// Coordinates beyond this are refused, as in the other readers.
const LIMIT: f64 = 1e15;
/// Most vertices or triangles in a shape (indices are 32-bit).
const MAX_COUNT: u64 = 1 << 30;
/// DEFLATE expands at most ~1032 times (zlib's technical details): a larger
/// stream is not a zlib stream of this file.
const MAX_RATIO: u64 = 1032;

/// Reads shape `shape_index` of a serialized file.
pub fn load_serialized(path: &Path, shape_index: u32) -> Result<SerializedMesh, String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot open the serialized file {shown}: {e}"))?;
    if !meta.is_file() {
        return Err(format!("cannot read the serialized file {shown}: it is not a regular file"));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read the serialized file {shown}: {e}"))?;
    parse(&bytes, shape_index).map_err(|e| format!("serialized file {shown}, shape {shape_index}, {e}"))
}

/// The number of shapes in a serialized file's bytes (its dictionary's count).
pub fn shape_count(bytes: &[u8]) -> Result<u32, String> {
    let version = header(bytes, 0)?;
    Ok(dictionary(bytes, version)?.len() as u32)
}

/// Parses shape `shape_index` of a serialized file's bytes; errors name the
/// byte (the caller adds the file and shape).
pub fn parse(bytes: &[u8], shape_index: u32) -> Result<SerializedMesh, String> {
    let version = header(bytes, 0)?;
    let offsets = dictionary(bytes, version)?;
    let Some(&start) = offsets.get(shape_index as usize) else {
        return Err(format!("the file holds {} shapes (0..{})", offsets.len(), offsets.len().saturating_sub(1)));
    };
    if header(bytes, start)? != version {
        return Err(format!("byte {start}: the shape's version differs from the file's ({version})"));
    }
    // The stream ends where the next shape (or the dictionary) begins.
    let end =
        offsets.iter().copied().filter(|&o| o > start).min().unwrap_or(dictionary_start(bytes, &offsets, version));
    let compressed = &bytes[start + 4..end.max(start + 4)];
    let limit = (compressed.len() as u64).saturating_mul(MAX_RATIO);
    let mut data = Vec::new();
    ZlibDecoder::new(compressed)
        .take(limit)
        .read_to_end(&mut data)
        .map_err(|e| format!("byte {}: the zlib stream is corrupt ({e})", start + 4))?;
    shape(&data, version).map_err(|e| format!("{e} (of the shape's stream, which starts at byte {})", start + 4))
}

/// Checks the header at `at` and returns its version.
fn header(bytes: &[u8], at: usize) -> Result<u16, String> {
    let Some(h) = bytes.get(at..at + 4) else {
        return Err(format!("byte {at}: the file ends inside a shape's header"));
    };
    let magic = u16::from_le_bytes([h[0], h[1]]);
    if magic != MAGIC {
        return Err(format!("byte {at}: not a serialized mesh (header {magic:#06x}, expected {MAGIC:#06x})"));
    }
    match u16::from_le_bytes([h[2], h[3]]) {
        v @ (3 | 4) => Ok(v),
        v => Err(format!("byte {}: version {v} is not supported (3 and 4 are)", at + 2)),
    }
}

/// The shapes' offsets from the end-of-file dictionary, each checked to lie
/// before the dictionary.
fn dictionary(bytes: &[u8], version: u16) -> Result<Vec<usize>, String> {
    let len = bytes.len();
    let count_at = len.checked_sub(4).ok_or("the file is too short for a dictionary")?;
    let count = u32::from_le_bytes(bytes[count_at..].try_into().expect("four bytes")) as usize;
    let width = if version == 3 { 4 } else { 8 };
    let start = count
        .checked_mul(width)
        .and_then(|n| count_at.checked_sub(n))
        .filter(|&s| s >= 4 && count > 0)
        .ok_or_else(|| format!("byte {count_at}: a dictionary of {count} shapes does not fit the file"))?;
    let mut offsets = Vec::with_capacity(count);
    for i in 0..count {
        let at = start + i * width;
        let o = if width == 4 {
            u32::from_le_bytes(bytes[at..at + 4].try_into().expect("four bytes")) as u64
        } else {
            u64::from_le_bytes(bytes[at..at + 8].try_into().expect("eight bytes"))
        };
        if o.saturating_add(4) > start as u64 || (i == 0 && o != 0) {
            return Err(format!("byte {at}: shape {i}'s offset {o} is not within the shapes ({start} bytes)"));
        }
        offsets.push(o as usize);
    }
    Ok(offsets)
}

fn dictionary_start(bytes: &[u8], offsets: &[usize], version: u16) -> usize {
    bytes.len() - 4 - offsets.len() * if version == 3 { 4 } else { 8 }
}

/// A cursor over a decompressed stream.
struct Stream<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Stream<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len()).ok_or_else(|| {
            format!("byte {}: the stream ends inside {what} ({} bytes left, {n} needed)", self.pos, self.left())
        })?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn left(&self) -> usize {
        self.data.len() - self.pos
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().expect("four bytes")))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().expect("eight bytes")))
    }

    /// `n` vectors of `dim` floats of `size` bytes, each coordinate finite
    /// and within [`LIMIT`]; the count was checked against the stream.
    fn floats(&mut self, n: usize, dim: usize, size: usize, what: &str) -> Result<Vec<[f32; 3]>, String> {
        let start = self.pos;
        let raw = self.take(n * dim * size, what)?;
        let mut out = Vec::with_capacity(n);
        for (i, item) in raw.chunks_exact(dim * size).enumerate() {
            let mut v = [0.0f32; 3];
            for (k, c) in item.chunks_exact(size).enumerate() {
                let x = if size == 4 {
                    f32::from_le_bytes(c.try_into().expect("four bytes")) as f64
                } else {
                    f64::from_le_bytes(c.try_into().expect("eight bytes"))
                };
                if !(x.abs() <= LIMIT) {
                    let at = start + (i * dim + k) * size;
                    return Err(format!(
                        "byte {at}: {what} {i} has coordinate {x}, not a finite number within {LIMIT:e}"
                    ));
                }
                v[k] = x as f32;
            }
            out.push(v);
        }
        Ok(out)
    }
}

fn shape(data: &[u8], version: u16) -> Result<SerializedMesh, String> {
    let mut s = Stream { data, pos: 0 };
    let flags = s.u32("the flags")?;
    if flags & !KNOWN != 0 {
        return Err(format!("byte 0: unknown flags {:#x}", flags & !KNOWN));
    }
    let size = match (flags & SINGLE != 0, flags & DOUBLE != 0) {
        (_, false) => 4,
        (false, true) => 8,
        (true, true) => return Err("byte 0: the flags ask for both single and double precision".into()),
    };
    let name = if version == 4 {
        let end = s.data[s.pos..]
            .iter()
            .position(|&b| b == 0)
            .ok_or_else(|| format!("byte {}: the name has no end", s.pos))?;
        let name = String::from_utf8_lossy(&s.data[s.pos..s.pos + end]).into_owned();
        s.pos += end + 1;
        name
    } else {
        String::new()
    };
    let count_at = s.pos;
    let vertices = s.u64("the vertex count")?;
    let triangles = s.u64("the triangle count")?;
    let per_vertex = size as u64
        * (3 + [(HAS_NORMALS, 3), (HAS_UVS, 2), (HAS_COLORS, 3)]
            .iter()
            .filter(|(f, _)| flags & f != 0)
            .map(|p| p.1)
            .sum::<u64>());
    if vertices > MAX_COUNT || triangles > MAX_COUNT {
        return Err(format!("byte {count_at}: {vertices} vertices or {triangles} triangles are more than {MAX_COUNT}"));
    }
    let needed = vertices * per_vertex + triangles * 12;
    if needed > s.left() as u64 {
        return Err(format!(
            "byte {count_at}: {vertices} vertices and {triangles} triangles need {needed} bytes, the stream has {}",
            s.left()
        ));
    }
    let (nv, nt) = (vertices as usize, triangles as usize);
    let vec3 = |v: Vec<[f32; 3]>| v.into_iter().map(Vec3::from).collect::<Vec<_>>();
    let positions = vec3(s.floats(nv, 3, size, "position")?);
    let normals = if flags & HAS_NORMALS != 0 { Some(vec3(s.floats(nv, 3, size, "normal")?)) } else { None };
    let uvs = if flags & HAS_UVS != 0 {
        Some(s.floats(nv, 2, size, "texture coordinate")?.into_iter().map(|[u, v, _]| Vec2::new(u, v)).collect())
    } else {
        None
    };
    let colors = if flags & HAS_COLORS != 0 { Some(vec3(s.floats(nv, 3, size, "colour")?)) } else { None };
    let start = s.pos;
    let raw = s.take(nt * 12, "the triangles")?;
    let mut tris = Vec::with_capacity(nt);
    for (i, t) in raw.chunks_exact(12).enumerate() {
        let t: [u32; 3] =
            std::array::from_fn(|k| u32::from_le_bytes(t[4 * k..4 * k + 4].try_into().expect("four bytes")));
        if let Some(k) = t.iter().position(|&v| v as u64 >= vertices) {
            return Err(format!("byte {}: triangle {i} names vertex {} of {vertices}", start + i * 12 + 4 * k, t[k]));
        }
        tris.push(t);
    }
    if s.left() != 0 {
        return Err(format!("byte {}: {} bytes follow the triangles", s.pos, s.left()));
    }
    Ok(SerializedMesh {
        name,
        face_normals: flags & FACE_NORMALS != 0,
        mesh: PlyMesh { positions, normals, uvs, colors, triangles: tris, attributes: Vec::new() },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::write::ZlibEncoder;
    use std::io::Write;

    /// One shape's body, as Mitsuba writes it, before compression.
    fn body(version: u16, double: bool, name: &str, with_normals: bool) -> Vec<u8> {
        let mut b = Vec::new();
        let flags =
            HAS_UVS | HAS_COLORS | if double { DOUBLE } else { SINGLE } | if with_normals { HAS_NORMALS } else { 0 };
        b.extend(flags.to_le_bytes());
        if version == 4 {
            b.extend(name.as_bytes());
            b.push(0);
        }
        b.extend(4u64.to_le_bytes());
        b.extend(2u64.to_le_bytes());
        let mut floats = |vals: &[f64]| {
            for &x in vals {
                if double {
                    b.extend(x.to_le_bytes());
                } else {
                    b.extend((x as f32).to_le_bytes());
                }
            }
        };
        floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.1]);
        if with_normals {
            floats(&[0.0, 0.0, 1.0].repeat(4));
        }
        floats(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0]);
        floats(&[0.5, 0.25, 1.0].repeat(4));
        for i in [0u32, 1, 2, 0, 2, 3] {
            b.extend(i.to_le_bytes());
        }
        b
    }

    fn file(version: u16, bodies: &[Vec<u8>]) -> Vec<u8> {
        let mut f = Vec::new();
        let mut offsets = Vec::new();
        for b in bodies {
            offsets.push(f.len() as u64);
            f.extend(MAGIC.to_le_bytes());
            f.extend(version.to_le_bytes());
            let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            z.write_all(b).unwrap();
            f.extend(z.finish().unwrap());
        }
        for o in &offsets {
            if version == 3 {
                f.extend((*o as u32).to_le_bytes());
            } else {
                f.extend(o.to_le_bytes());
            }
        }
        f.extend((offsets.len() as u32).to_le_bytes());
        f
    }

    #[test]
    fn single_and_double_precision_shapes_read_by_index() {
        for version in [3u16, 4] {
            let f = file(version, &[body(version, false, "quad", true), body(version, true, "second", false)]);
            assert_eq!(shape_count(&f).unwrap(), 2);
            for (index, double) in [(0, false), (1, true)] {
                let s = parse(&f, index).unwrap();
                let m = &s.mesh;
                assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
                assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
                assert_eq!(m.positions[3], Vec3::new(0.0, 1.0, 0.1f64 as f32), "double {double}");
                assert_eq!(m.normals.is_some(), !double);
                assert_eq!(m.uvs.as_ref().unwrap()[2], Vec2::new(1.0, 1.0));
                assert_eq!(m.colors.as_ref().unwrap()[1], Vec3::new(0.5, 0.25, 1.0));
                assert!(!s.face_normals);
                let name = if version == 4 { ["quad", "second"][index as usize] } else { "" };
                assert_eq!(s.name, name);
            }
            let e = parse(&f, 2).unwrap_err();
            assert!(e.contains("2 shapes"), "{e}");
        }
    }

    #[test]
    fn corrupt_files_are_refused_where_they_go_wrong() {
        let good = file(4, &[body(4, false, "quad", true)]);
        // Truncated anywhere: refused, never a panic.
        for cut in 0..good.len() {
            assert!(parse(&good[..cut], 0).is_err(), "cut at {cut}");
        }
        let mut bad = good.clone();
        bad[0] = 0x1d;
        assert!(parse(&bad, 0).unwrap_err().starts_with("byte 0: not a serialized mesh"));
        let mut bad = good.clone();
        bad[2] = 5;
        assert!(parse(&bad, 0).unwrap_err().starts_with("byte 2: version 5"));
        // A dictionary offset beyond the shapes.
        let mut bad = good.clone();
        let n = bad.len();
        bad[n - 2] = 0xff;
        assert!(parse(&bad, 0).unwrap_err().contains("does not fit"), "{}", parse(&bad, 0).unwrap_err());
        // Garbage in the zlib stream.
        let mut bad = good.clone();
        bad[7] ^= 0xff;
        bad[8] ^= 0xff;
        let e = parse(&bad, 0).unwrap_err();
        assert!(e.starts_with("byte 4: the zlib stream is corrupt"), "{e}");
        // A vertex count far beyond the stream, and an index out of range.
        let mut b = body(4, false, "quad", true);
        b[9..17].copy_from_slice(&(1u64 << 29).to_le_bytes());
        let e = parse(&file(4, &[b]), 0).unwrap_err();
        assert!(e.starts_with("byte 9: 536870912 vertices and 2 triangles need"), "{e}");
        let mut b = body(4, false, "quad", true);
        let n = b.len();
        b[n - 4..].copy_from_slice(&7u32.to_le_bytes());
        let e = parse(&file(4, &[b]), 0).unwrap_err();
        assert!(e.starts_with(&format!("byte {}: triangle 1 names vertex 7 of 4", n - 4)), "{e}");
        // A non-finite coordinate.
        let mut b = body(3, true, "", false);
        b[20..28].copy_from_slice(&f64::NAN.to_le_bytes());
        let e = parse(&file(3, &[b]), 0).unwrap_err();
        assert!(e.starts_with("byte 20: position 0 has coordinate NaN"), "{e}");
    }

    #[test]
    fn directories_are_refused_with_the_file_named() {
        let dir = std::env::temp_dir();
        let e = load_serialized(&dir, 0).unwrap_err();
        assert!(e.contains("not a regular file") && e.contains(&dir.display().to_string()), "{e}");
    }
}
