//! What a render did and what it cost: the counters each thread keeps while
//! it shades ([`Counters`]) and the render's totals and times ([`Stats`]).
//! A new statistic is a field here and a line of the summary
//! (`render::summary`, or its method's part of it).

use std::time::Duration;

/// What a thread counted while it shaded; summed over threads by [`merge`](Counters::merge).
#[derive(Clone, Copy, Debug, Default)]
pub struct Counters {
    /// Rays cast.
    pub rays: u64,
    /// Samples whose radiance came out non-finite (a bug at some
    /// estimator; never written).
    pub nonfinite: u64,
    /// Shadow rays not cast: the light's back faced the point.
    pub shadow_rays_skipped: u64,
    /// Caustic estimates made, and those a pixel's earlier sample answered.
    pub caustic_estimates: u64,
    pub caustic_reused: u64,
    /// First non-finite sample seen: (pixel index, estimator name).
    first_nonfinite: Option<(u64, &'static str)>,
}

impl Counters {
    pub fn merge(mut self, other: Counters) -> Counters {
        self.rays += other.rays;
        self.nonfinite += other.nonfinite;
        self.shadow_rays_skipped += other.shadow_rays_skipped;
        self.caustic_estimates += other.caustic_estimates;
        self.caustic_reused += other.caustic_reused;
        if let Some((pixel, estimator)) = other.first_nonfinite {
            self.note_nonfinite(pixel, estimator);
        }
        self
    }

    /// Remembers the non-finite sample of the lowest pixel index, so the
    /// report does not depend on the order threads finished in.
    pub fn note_nonfinite(&mut self, pixel: u64, estimator: &'static str) {
        if self.first_nonfinite.is_none_or(|(p, _)| pixel < p) {
            self.first_nonfinite = Some((pixel, estimator));
        }
    }

    pub fn first_nonfinite(&self) -> Option<(u64, &'static str)> {
        self.first_nonfinite
    }
}

/// What a render did and what it cost.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub global_emitted: u64,
    /// Global-pass photons whose first ray met the scene (fewer than
    /// emitted where light from outside misses it).
    pub global_landed: u64,
    pub global_stored: usize,
    pub caustic_emitted: u64,
    pub caustic_stored: usize,
    /// Caustic-pass photons whose first hit was mirror or glass.
    pub caustic_aimed_hits: u64,
    /// Per caustic target: its object (the scene file's shape index), the
    /// photons aimed at it, and those whose first hit was mirror or glass.
    pub caustic_targets: Vec<(u32, u64, u64)>,
    /// Global-pass photons whose first hit was mirror or glass (what the
    /// caustic pass would get without aiming).
    pub global_specular_hits: u64,
    pub cache_points: usize,
    /// Bright spots final gathering aims at.
    pub spots: usize,
    pub map_bytes: usize,
    pub photon_rays: u64,
    /// The camera pass's counters.
    pub camera: Counters,
    /// Pixels on the rim of a light's image, sampled with `edge_spp`.
    pub edge_pixels: usize,
    /// The emitted part's samples in each of them (`Settings::edge_spp`,
    /// or fewer where the rims are many).
    pub edge_spp: u32,
    pub photon_time: Duration,
    /// The map build: the photon maps (the caustic map's Morton sort and
    /// kd-tree, both maps' grids), then the irradiance cache (estimates at
    /// photons, their grid and tree).
    pub tree_time: Duration,
    pub cache_time: Duration,
    pub camera_time: Duration,
    /// Radius caps and photons per estimate (of the last pass when progressive).
    pub r_global: f32,
    pub r_caustic: f32,
    pub k_global: usize,
    pub k_caustic: usize,
    /// Passes rendered (1 for a classic render).
    pub passes: u32,
    /// Photon maps the scene cannot use, not built.
    pub skipped_global: bool,
    pub skipped_caustic: bool,
}

impl Stats {
    pub fn build_time(&self) -> Duration {
        self.tree_time + self.cache_time
    }

    /// Adds another pass's counts and times (maps' sizes are the last pass's).
    pub fn absorb(&mut self, o: Stats) {
        self.global_emitted += o.global_emitted;
        self.global_landed += o.global_landed;
        self.caustic_emitted += o.caustic_emitted;
        self.caustic_aimed_hits += o.caustic_aimed_hits;
        if self.caustic_targets.len() < o.caustic_targets.len() {
            self.caustic_targets = o.caustic_targets.iter().map(|&(object, _, _)| (object, 0, 0)).collect();
        }
        for (a, b) in self.caustic_targets.iter_mut().zip(&o.caustic_targets) {
            a.1 += b.1;
            a.2 += b.2;
        }
        self.global_specular_hits += o.global_specular_hits;
        self.photon_rays += o.photon_rays;
        self.camera = self.camera.merge(o.camera);
        self.photon_time += o.photon_time;
        self.tree_time += o.tree_time;
        self.cache_time += o.cache_time;
        self.camera_time += o.camera_time;
        self.passes += o.passes;
        self.global_stored = o.global_stored;
        self.caustic_stored = o.caustic_stored;
        self.cache_points = o.cache_points;
        self.spots = o.spots;
        self.map_bytes = o.map_bytes;
        self.edge_pixels = o.edge_pixels;
        self.edge_spp = o.edge_spp;
        self.r_global = o.r_global;
        self.r_caustic = o.r_caustic;
        self.k_global = o.k_global;
        self.k_caustic = o.k_caustic;
        self.skipped_global = o.skipped_global;
        self.skipped_caustic = o.skipped_caustic;
    }
}

/// `n` things, in the singular for one: "1 pass", "2 passes".
pub fn counted(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
