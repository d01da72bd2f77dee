//! Memory: what a render will need at its peak, and what the system can
//! give, so that a render that would not fit is refused before it allocates.

use crate::render::settings::Settings;

impl Settings {
    /// Bytes the render will hold at its peak, from the peak resident size
    /// measured on the default scene (`/usr/bin/time -v`, 100 x 100):
    /// 0.98 GB at 2e6 + 2e6 photons, 4.82 GB at 1e7 + 1e7. That is ~5
    /// stored global photons per emitted one (Russian roulette with albedo
    /// 0.8), each 88 bytes at the peak (28 for the photon, the rest its
    /// grid index and the per-thread blocks the map is gathered from), and
    /// ~40 bytes per emitted caustic photon (its map is built after the
    /// global map's peak); the film in f32 and its rows in flight; for a
    /// progressive render, the passes' exact sums (144 bytes a pixel) and
    /// the average.
    pub fn estimated_peak_bytes(&self, progressive: bool) -> u64 {
        let global = self.photons.saturating_mul(5 * 88);
        let caustic = self.caustic_photons.saturating_mul(40);
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

#[cfg(test)]
mod tests {
    use crate::render::settings::Settings;

    /// The peaks measured (see the doc comment), within 5%.
    #[test]
    fn the_estimate_matches_the_measured_peaks() {
        for (photons, measured) in [(2_000_000u64, 0.976e9), (10_000_000, 4.822e9)] {
            let s = Settings { photons, caustic_photons: photons, width: 100, height: 100, ..Settings::default() };
            let ratio = s.estimated_peak_bytes(false) as f64 / measured;
            assert!((0.95..1.05).contains(&ratio), "{photons}: estimate / measured {ratio:.3}");
        }
    }
}
