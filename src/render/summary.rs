//! The summary a program prints at the end of a render: every line within
//! 100 columns.

use super::method::RenderMethod;
use crate::settings::Settings;
use crate::stats::{counted, Stats};
use std::path::PathBuf;
use std::time::Duration;

/// A render's summary.
pub struct Summary<'a> {
    pub stats: &'a Stats,
    pub settings: &'a Settings,
    /// The method rendered with: its own lines.
    pub method: &'a dyn RenderMethod,
    pub threads: usize,
    /// Reading the scene file and building the scene (its BVH).
    pub load_time: Duration,
    pub write_time: Duration,
    pub total_time: Duration,
    pub written: &'a [PathBuf],
}

impl Summary<'_> {
    pub fn lines(&self) -> Vec<String> {
        let s = self.stats;
        let st = self.settings;
        let own = self.method.summary(s);
        let secs = |d: Duration| d.as_secs_f64();
        let per_s = |n: u64, d: Duration| n as f64 / secs(d).max(1e-9) / 1e6;
        let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
        let (passes, threads) =
            (counted(s.passes as u64, "pass", "passes"), counted(self.threads as u64, "thread", "threads"));
        let title = self.method.method().title();
        let mut out = vec![format!("photonmap: {title}, {passes}, {threads}, {} x {}", st.width, st.height)];
        out.push(format!("  scene load   {:>8.3} s", secs(self.load_time)));
        out.extend(own.lines);
        out.push(format!(
            "  camera pass  {:>8.3} s  {:>7.2} M rays/s  ({} spp{}, {} shadow rays)",
            secs(s.camera_time),
            per_s(s.camera.rays, s.camera_time),
            st.spp,
            own.camera,
            st.shadow_rays
        ));
        if s.edge_pixels > 0 {
            out.push(format!(
                "               {} pixels on a light's rim took {} extra samples",
                s.edge_pixels, st.edge_spp
            ));
        }
        let c = &s.camera;
        if c.caustic_estimates + c.caustic_reused > 0 {
            out.push(format!(
                "               {} caustic estimates, {} reused within a pixel ({:.0}%)",
                c.caustic_estimates,
                c.caustic_reused,
                pct(c.caustic_reused, c.caustic_estimates + c.caustic_reused)
            ));
        }
        let mut skipped = own.skipped;
        if c.shadow_rays_skipped > 0 {
            skipped.push(format!("{} shadow rays to lights facing away", c.shadow_rays_skipped));
        }
        for (i, what) in skipped.iter().enumerate() {
            out.push(format!("  {}  {what}", if i == 0 { "skipped:  " } else { "          " }));
        }
        out.push(format!("  write        {:>8.3} s", secs(self.write_time)));
        for path in self.written {
            out.push(format!("               {}", path.display()));
        }
        out.push(format!("  total        {:>8.3} s", secs(self.total_time)));
        out
    }
}
