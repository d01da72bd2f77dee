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
    /// Rays cast between an irradiance-cache lookup and a cache point at
    /// another level than its surface, and those that found it hidden.
    pub cache_rays: u64,
    pub cache_hidden: u64,
    /// Runs whose rim pixels were not sought because a probe of the
    /// emitted part cost more rays than a whole sample (render::rims), so
    /// that the summary can say why there are none.
    pub rims_too_costly: u64,
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
        self.cache_rays += other.cache_rays;
        self.cache_hidden += other.cache_hidden;
        self.rims_too_costly += other.rims_too_costly;
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

/// How a pass's value of a statistic joins a render's: added (`sum`), the
/// last pass's (`last`: map sizes, radii), or merged ([`Absorb`]).
macro_rules! join {
    (sum, $total:expr, $pass:expr) => {
        $total += $pass
    };
    (last, $total:expr, $pass:expr) => {
        $total = $pass
    };
    (merge, $total:expr, $pass:expr) => {
        Absorb::absorb(&mut $total, $pass)
    };
}

/// The render's statistics: each field declared once, with how a pass's
/// value joins the render's, so that [`Stats::absorb`] cannot miss one.
macro_rules! stats {
    ($($(#[$doc:meta])* $name:ident: $ty:ty => $how:ident,)*) => {
        /// What a render did and what it cost.
        #[derive(Clone, Debug, Default)]
        pub struct Stats {
            $($(#[$doc])* pub $name: $ty,)*
        }

        impl Stats {
            /// Adds another pass's counts and times (maps' sizes and radii
            /// are the last pass's).
            pub fn absorb(&mut self, pass: Stats) {
                $(join!($how, self.$name, pass.$name);)*
            }
        }
    };
}

stats! {
    global_emitted: u64 => sum,
    /// Global-pass photons whose first ray met the scene (fewer than
    /// emitted where light from outside misses it).
    global_landed: u64 => sum,
    global_stored: usize => last,
    caustic_emitted: u64 => sum,
    caustic_stored: usize => last,
    /// Caustic-pass photons whose first hit was mirror or glass.
    caustic_aimed_hits: u64 => sum,
    /// Per caustic target: its object (the scene file's shape index), the
    /// photons aimed at it, and those whose first hit was mirror or glass.
    caustic_targets: Vec<(u32, u64, u64)> => merge,
    /// Global-pass photons whose first hit was mirror or glass (what the
    /// caustic pass would get without aiming).
    global_specular_hits: u64 => sum,
    cache_points: usize => last,
    /// Shadow rays cast for the irradiance cache's direct light.
    cache_rays: u64 => sum,
    /// Bright spots final gathering aims at.
    spots: usize => last,
    map_bytes: usize => last,
    photon_rays: u64 => sum,
    /// The camera pass's counters.
    camera: Counters => merge,
    /// Pixels on the rim of a light's image, sampled with `edge_spp`.
    edge_pixels: usize => last,
    /// The emitted part's samples in each of them (`Settings::edge_spp`,
    /// or fewer where the rims are many), on average (rounded down) and
    /// at most (more than the average where the rims' share went by their
    /// probes' spread: render::rims).
    edge_spp: u32 => last,
    edge_spp_max: u32 => last,
    /// Pixels whose camera samples a pass were raised by the adaptive
    /// counts (render::adaptive), and the samples added a pass.
    adaptive_pixels: usize => last,
    adaptive_samples: u64 => last,
    photon_time: Duration => sum,
    /// The map build: the photon maps (the caustic map's Morton sort and
    /// kd-tree, both maps' grids), then the irradiance cache (estimates at
    /// photons, their grid and tree).
    tree_time: Duration => sum,
    cache_time: Duration => sum,
    camera_time: Duration => sum,
    /// Radius caps and photons per estimate (of the last pass when progressive).
    r_global: f32 => last,
    r_caustic: f32 => last,
    k_global: usize => last,
    k_caustic: usize => last,
    /// Passes rendered (1 for a classic render).
    passes: u32 => sum,
    /// Photon maps the scene cannot use, not built.
    skipped_global: bool => last,
    skipped_caustic: bool => last,
}

/// A statistic that joins a render's otherwise than by a sum.
pub trait Absorb {
    fn absorb(&mut self, pass: Self);
}

impl Absorb for Counters {
    fn absorb(&mut self, pass: Counters) {
        *self = self.merge(pass);
    }
}

/// Per target, photons aimed and hits: added target by target (a later
/// pass may know more targets).
impl Absorb for Vec<(u32, u64, u64)> {
    fn absorb(&mut self, pass: Self) {
        if self.len() < pass.len() {
            *self = pass.iter().map(|&(object, _, _)| (object, 0, 0)).collect();
        }
        for (a, b) in self.iter_mut().zip(&pass) {
            a.1 += b.1;
            a.2 += b.2;
        }
    }
}

impl Stats {
    pub fn build_time(&self) -> Duration {
        self.tree_time + self.cache_time
    }
}

/// `n` things, in the singular for one: "1 pass", "2 passes".
pub fn counted(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts add up, sizes and radii are the last pass's, targets add up
    /// target by target.
    #[test]
    fn a_pass_joins_the_render_as_each_field_says() {
        let pass = |i: u64| Stats {
            global_emitted: 10 * i,
            global_stored: i as usize,
            cache_rays: 100,
            caustic_targets: vec![(3, i, 1)],
            camera: Counters { rays: 7, ..Counters::default() },
            r_global: i as f32,
            passes: 1,
            photon_time: Duration::from_millis(5),
            ..Stats::default()
        };
        let mut total = Stats::default();
        for i in 1..=3 {
            total.absorb(pass(i));
        }
        assert_eq!((total.global_emitted, total.global_stored, total.cache_rays), (60, 3, 300));
        assert_eq!(total.caustic_targets, vec![(3, 6, 3)]);
        assert_eq!((total.camera.rays, total.r_global, total.passes), (21, 3.0, 3));
        assert_eq!(total.photon_time, Duration::from_millis(15));
    }
}
