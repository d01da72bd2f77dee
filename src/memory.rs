//! Memory: what a render will need at its peak, and what the system can
//! give, so that a render that would not fit is refused before it allocates.

use crate::settings::Settings;

impl Settings {
    /// Bytes the render will hold at its peak, estimated from the measured
    /// default scene: ~5 stored global photons per emitted one (Russian
    /// roulette with albedo 0.8), each 28 bytes plus ~16 in the kd-tree and
    /// as much again while the tree is built (a bound: a global map that
    /// keeps its grid builds no tree); one caustic photon per emitted
    /// one; the film in f32 and its rows in flight; for a progressive
    /// render, the passes' exact sums (144 bytes a pixel) and the average.
    pub fn estimated_peak_bytes(&self, progressive: bool) -> u64 {
        let per_photon = std::mem::size_of::<crate::photon::Photon>() as u64 + 16 + 24;
        let global = self.photons.saturating_mul(5).saturating_mul(per_photon);
        let caustic = self.caustic_photons.saturating_mul(per_photon);
        let pixels = (self.width as u64) * (self.height as u64);
        let film = pixels * 2 * 12 + if progressive { pixels * (144 + 12 * 4) } else { 0 };
        global.saturating_add(caustic).saturating_add(film)
    }
}

/// Memory the system can give this process (Linux: MemAvailable), if known:
/// renders that would not fit are refused before they allocate.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
