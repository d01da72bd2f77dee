//! Memory: what a render will need at its peak, and what the system can
//! give, so that a render that would not fit is refused before it allocates.

use crate::render::settings::Settings;

impl Settings {
    /// Bytes the render will hold at its peak, from the peak resident size
    /// of `photonmap` on the default scene (100 x 100, 1 spp, 2 threads;
    /// 2-core AMD EPYC VM): 9.7 MB with no photons, 345 MB at 1e6 global
    /// photons, 405 MB at 1e6 + 1e6. That is ~5 stored global photons per
    /// emitted one (Russian roulette with albedo 0.8), each ~67 bytes at
    /// the peak (28 for the photon, the rest its grid index and the blocks
    /// the map is gathered from), and ~60 bytes per emitted caustic photon
    /// (its map is built after the global map's peak); the program itself;
    /// the film in f32 and its rows in flight; for a progressive render,
    /// the passes' exact sums (144 bytes a pixel) and the average.
    /// tests/memory.rs measures it again.
    pub fn estimated_peak_bytes(&self, progressive: bool) -> u64 {
        let global = self.photons.saturating_mul(5 * 67);
        let caustic = self.caustic_photons.saturating_mul(60);
        let pixels = (self.width as u64) * (self.height as u64);
        let film = pixels * 2 * 12 + if progressive { pixels * (144 + 12 * 4) } else { 0 };
        PROGRAM_BYTES.saturating_add(global).saturating_add(caustic).saturating_add(film)
    }
}

/// The resident size of the program with no photons (its code, the
/// scene, the threads' stacks).
const PROGRAM_BYTES: u64 = 10_000_000;

/// Memory the system can give this process (Linux: MemAvailable), if known:
/// renders that would not fit are refused before they allocate.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
