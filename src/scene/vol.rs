//! Mitsuba's binary volume grid (`.vol`), as its `VolumeGrid::read`
//! defines it (src/render/volumegrid.cpp), little-endian: the bytes "VOL",
//! version 3, the data type (1: 32-bit floats, the only one Mitsuba 3
//! reads), the resolution along x, y and z (32-bit integers), the channel
//! count, a bounding box (six floats: min then max), then the samples,
//! channels innermost, then x, y and z outermost.
//!
//! The whole file is read at once after its header has said how long it
//! must be: a shorter or longer file is refused naming both lengths, so a
//! truncated grid is never read as a smaller one.

use std::path::Path;

/// A grid of samples as the file holds them.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeGrid {
    /// Samples along x, y and z.
    pub size: [usize; 3],
    pub channels: usize,
    /// The box the file gives (min, max); Mitsuba's shapes place grids by
    /// their own transforms instead.
    pub bbox: ([f32; 3], [f32; 3]),
    /// Channel fastest, then x, y, z.
    pub data: Vec<f32>,
}

/// The header's 48 bytes.
const HEADER: usize = 48;

/// Reads `path`; an error says what is wrong and where (a byte offset).
pub fn load_vol(path: &Path) -> Result<VolumeGrid, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!("{}: not a regular file", path.display()));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The grid in `bytes` (a whole `.vol` file).
pub fn parse(bytes: &[u8]) -> Result<VolumeGrid, String> {
    if bytes.len() < HEADER {
        return Err(format!("{} bytes: a volume grid's header alone is {HEADER}", bytes.len()));
    }
    if &bytes[..3] != b"VOL" {
        return Err("byte 0: not a volume grid (it does not start with \"VOL\")".into());
    }
    if bytes[3] != 3 {
        return Err(format!("byte 3: version {} (Mitsuba 3 reads version 3)", bytes[3]));
    }
    let int = |at: usize| i32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let float = |at: usize| f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    if int(4) != 1 {
        return Err(format!("byte 4: data type {} (only 1, 32-bit floats, is read, as in Mitsuba 3)", int(4)));
    }
    let mut size = [0usize; 3];
    for (a, at) in [8, 12, 16].into_iter().enumerate() {
        size[a] = usize::try_from(int(at))
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("byte {at}: resolution {} along {} (at least 1)", int(at), ["x", "y", "z"][a]))?;
    }
    let channels =
        usize::try_from(int(20)).ok().filter(|&n| n > 0).ok_or_else(|| format!("byte 20: {} channels", int(20)))?;
    let count = size
        .iter()
        .try_fold(channels, |n, &s| n.checked_mul(s))
        .filter(|n| n.checked_mul(4).is_some_and(|b| b <= isize::MAX as usize - HEADER))
        .ok_or_else(|| format!("byte 8: {} x {} x {} x {channels} samples is too many", size[0], size[1], size[2]))?;
    let want = HEADER + 4 * count;
    if bytes.len() != want {
        return Err(format!(
            "{} bytes, where a grid of {} x {} x {} with {channels} channel(s) takes {want}",
            bytes.len(),
            size[0],
            size[1],
            size[2]
        ));
    }
    let bbox = ([float(24), float(28), float(32)], [float(36), float(40), float(44)]);
    let data = bytes[HEADER..].chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    Ok(VolumeGrid { size, channels, bbox, data })
}

/// The file of `grid` (for tests and exports).
pub fn to_bytes(grid: &VolumeGrid) -> Vec<u8> {
    let mut out = b"VOL\x03".to_vec();
    out.extend(1i32.to_le_bytes());
    for n in grid.size {
        out.extend((n as i32).to_le_bytes());
    }
    out.extend((grid.channels as i32).to_le_bytes());
    for x in grid.bbox.0.iter().chain(&grid.bbox.1) {
        out.extend(x.to_le_bytes());
    }
    for x in &grid.data {
        out.extend(x.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> VolumeGrid {
        VolumeGrid {
            size: [3, 2, 2],
            channels: 1,
            bbox: ([0.0; 3], [1.0; 3]),
            data: (0..12).map(|i| i as f32 * 0.5 - 1.0).collect(),
        }
    }

    #[test]
    fn a_grid_reads_back_as_written() {
        assert_eq!(parse(&to_bytes(&grid())).unwrap(), grid());
    }

    #[test]
    fn broken_files_are_refused_with_their_place() {
        let good = to_bytes(&grid());
        let cut = parse(&good[..good.len() - 2]).unwrap_err();
        assert!(cut.contains("94 bytes") && cut.contains("takes 96"), "{cut}");
        let mut bad = good.clone();
        bad[3] = 2;
        assert!(parse(&bad).unwrap_err().starts_with("byte 3: version 2"));
        let mut bad = good.clone();
        bad[4] = 2;
        assert!(parse(&bad).unwrap_err().starts_with("byte 4: data type 2"));
        let mut bad = good.clone();
        bad[8..12].copy_from_slice(&(-3i32).to_le_bytes());
        assert!(parse(&bad).unwrap_err().starts_with("byte 8: resolution -3 along x"));
        let mut bad = good;
        bad[8..12].copy_from_slice(&i32::MAX.to_le_bytes());
        bad[12..16].copy_from_slice(&i32::MAX.to_le_bytes());
        bad[16..20].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(parse(&bad).unwrap_err().contains("too many"));
        assert!(parse(b"VOL").unwrap_err().contains("header"));
        assert!(parse(&[b'X'; 60]).unwrap_err().starts_with("byte 0"));
    }
}
