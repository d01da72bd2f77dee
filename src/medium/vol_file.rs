//! Mitsuba's binary grid-volume format (`.vol`, version 3; the layout is
//! documented with Mitsuba 3's `gridvolume` plugin, src/volumes/grid.cpp,
//! and is Mitsuba 0.6's): little endian,
//!
//! | bytes | content |
//! |---|---|
//! | 0-2 | `V`, `O`, `L` |
//! | 3 | version, 3 |
//! | 4-7 | encoding (i32), 1: float32 |
//! | 8-19 | cells along x, y, z (i32 each) |
//! | 20-23 | channels (i32) |
//! | 24-47 | bounding box: xmin, ymin, zmin, xmax, ymax, zmax (f32) |
//! | 48- | values, `data[((z * ny + y) * nx + x) * channels + c]` |
//!
//! A bad file is refused at the byte where it goes wrong.

use std::path::Path;

/// A grid of values as a `.vol` file holds it.
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    /// Cells along x, y, z.
    pub res: [u32; 3],
    pub channels: u32,
    /// The box the file says its data spans (read by `use_grid_bbox`).
    pub bbox: ([f32; 3], [f32; 3]),
    /// x fastest, then y, then z; channels interleaved.
    pub data: Vec<f32>,
}

/// What is wrong with a `.vol` file, and at which byte.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("byte {offset}: {message}")]
pub struct VolError {
    pub offset: u64,
    pub message: String,
}

const HEADER: usize = 48;
/// The largest grid read (values, all channels): 2^30, 4 GiB of floats.
pub const MAX_VALUES: u64 = 1 << 30;

fn fail<T>(offset: usize, message: impl Into<String>) -> Result<T, VolError> {
    Err(VolError { offset: offset as u64, message: message.into() })
}

impl VolGrid {
    /// Reads a `.vol` file; the error names the file's byte (or the
    /// operating system's reason).
    pub fn read(path: &Path) -> Result<VolGrid, String> {
        let meta = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
        if !meta.is_file() {
            return Err(format!("{}: not a regular file", path.display()));
        }
        if meta.len() > HEADER as u64 + 4 * MAX_VALUES {
            return Err(format!("{}: {} bytes is larger than any grid photonmap reads", path.display(), meta.len()));
        }
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        VolGrid::parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Parses the bytes of a `.vol` file.
    pub fn parse(bytes: &[u8]) -> Result<VolGrid, VolError> {
        if bytes.len() < HEADER {
            return fail(bytes.len(), format!("the file ends inside its 48-byte header ({} bytes)", bytes.len()));
        }
        if &bytes[0..3] != b"VOL" {
            return fail(0, "not a volume file (it does not start with 'VOL')");
        }
        if bytes[3] != 3 {
            return fail(3, format!("version {} (photonmap reads version 3, as Mitsuba 3 does)", bytes[3]));
        }
        let i32_at = |o: usize| i32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        let f32_at = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        let encoding = i32_at(4);
        if encoding != 1 {
            return fail(4, format!("encoding {encoding} (only 1, float32, is defined)"));
        }
        let mut res = [0u32; 3];
        for (axis, r) in res.iter_mut().enumerate() {
            let n = i32_at(8 + 4 * axis);
            if n < 1 {
                return fail(8 + 4 * axis, format!("{} cells along {}: must be at least 1", n, ["x", "y", "z"][axis]));
            }
            *r = n as u32;
        }
        let channels = i32_at(20);
        if channels != 1 && channels != 3 {
            return fail(20, format!("{channels} channels (photonmap reads 1 or 3)"));
        }
        let mut lo = [0f32; 3];
        let mut hi = [0f32; 3];
        for k in 0..3 {
            lo[k] = f32_at(24 + 4 * k);
            hi[k] = f32_at(36 + 4 * k);
        }
        if let Some(k) = (0..6).find(|&k| !f32_at(24 + 4 * k).is_finite()) {
            return fail(24 + 4 * k, "the bounding box is not finite");
        }
        let values = res.iter().map(|&r| r as u64).product::<u64>() * channels as u64;
        if values > MAX_VALUES {
            return fail(8, format!("{values} values is more than photonmap reads ({MAX_VALUES})"));
        }
        let want = HEADER as u64 + 4 * values;
        if (bytes.len() as u64) < want {
            return fail(
                bytes.len(),
                format!(
                    "the data ends early: {}x{}x{} cells of {channels} channel(s) need {want} bytes, the file has {}",
                    res[0],
                    res[1],
                    res[2],
                    bytes.len()
                ),
            );
        }
        if (bytes.len() as u64) > want {
            return fail(want as usize, format!("{} bytes follow the data", bytes.len() as u64 - want));
        }
        let mut data = Vec::with_capacity(values as usize);
        for (i, chunk) in bytes[HEADER..].chunks_exact(4).enumerate() {
            let v = f32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]);
            if !v.is_finite() {
                return fail(HEADER + 4 * i, format!("value {i} is not finite ({v})"));
            }
            data.push(v);
        }
        Ok(VolGrid { res, channels: channels as u32, bbox: (lo, hi), data })
    }

    /// The bytes of the file holding this grid.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER + 4 * self.data.len());
        out.extend_from_slice(b"VOL");
        out.push(3);
        out.extend_from_slice(&1i32.to_le_bytes());
        for r in self.res {
            out.extend_from_slice(&(r as i32).to_le_bytes());
        }
        out.extend_from_slice(&(self.channels as i32).to_le_bytes());
        for v in self.bbox.0.iter().chain(self.bbox.1.iter()) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in &self.data {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// The largest value over every cell and channel.
    pub fn max(&self) -> f32 {
        self.data.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> VolGrid {
        let data = (0..2 * 3 * 4 * 3).map(|i| i as f32 * 0.25).collect();
        VolGrid { res: [2, 3, 4], channels: 3, bbox: ([0.0, -1.0, 0.5], [1.0, 2.0, 3.0]), data }
    }

    #[test]
    fn a_grid_reads_back_as_written() {
        let g = grid();
        let bytes = g.to_bytes();
        assert_eq!(bytes.len(), 48 + 4 * 72);
        assert_eq!(VolGrid::parse(&bytes), Ok(g.clone()));
        assert_eq!(g.max(), 71.0 * 0.25);
    }

    /// Each way a file can be wrong is refused at its byte.
    #[test]
    fn bad_files_are_refused_where_they_go_wrong() {
        let good = grid().to_bytes();
        let offset = |bytes: &[u8]| VolGrid::parse(bytes).unwrap_err().offset;
        let with = |at: usize, v: &[u8]| {
            let mut b = good.clone();
            b[at..at + v.len()].copy_from_slice(v);
            b
        };
        assert_eq!(offset(&good[..20]), 20);
        assert_eq!(offset(&with(0, b"VOX")), 0);
        assert_eq!(offset(&with(3, &[2])), 3);
        assert_eq!(offset(&with(4, &2i32.to_le_bytes())), 4);
        assert_eq!(offset(&with(12, &0i32.to_le_bytes())), 12);
        assert_eq!(offset(&with(20, &6i32.to_le_bytes())), 20);
        assert_eq!(offset(&with(28, &f32::NAN.to_le_bytes())), 28);
        assert_eq!(offset(&good[..good.len() - 4]), good.len() as u64 - 4);
        let mut long = good.clone();
        long.extend_from_slice(&[0; 8]);
        assert_eq!(offset(&long), good.len() as u64);
        assert_eq!(offset(&with(48 + 4 * 5, &f32::INFINITY.to_le_bytes())), 48 + 4 * 5);
        let huge = with(8, &i32::MAX.to_le_bytes());
        assert_eq!(offset(&huge), 8);
        let msg = VolGrid::parse(&with(3, &[2])).unwrap_err().to_string();
        assert!(msg.starts_with("byte 3: version 2"), "{msg}");
    }
}
