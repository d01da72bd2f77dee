//! Every setting that decides a render, with its default: the command
//! lines take their defaults from here.

pub use crate::render::Method;

/// Everything that decides the image besides the scene.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub method: Method,
    /// Photons emitted for the global map.
    pub photons: u64,
    /// Photons emitted (aimed at mirrors and glass) for the caustic map.
    pub caustic_photons: u64,
    /// Camera samples per pixel.
    pub spp: u32,
    pub seed: u64,
    pub width: u32,
    pub height: u32,
    /// Nearest photons per global-map (irradiance) estimate.
    pub k_global: usize,
    /// Nearest photons per caustic estimate.
    pub k_caustic: usize,
    /// Search radius caps; `None`: a fraction of the scene's diagonal.
    pub r_global: Option<f32>,
    pub r_caustic: Option<f32>,
    pub gather_rays: u32,
    /// Of the gather rays at a diffuse camera hit, how many are aimed at the
    /// mirror and glass objects and bright spots it sees (where it sees
    /// any; one ray at least stays cosine-distributed).
    pub aimed_gather_rays: u32,
    pub shadow_rays: u32,
    /// Irradiance is precomputed at every n-th global photon; `None`: at
    /// every (k_global / CACHE_POINTS_PER_DISK)-th ([`cache_stride`]).
    pub cache_stride: Option<usize>,
    /// A pixel's later samples reuse its last caustic estimate where they
    /// land on the same surface within this fraction of that estimate's
    /// radius (0: every sample makes its own).
    pub caustic_reuse: f32,
    /// Samples of the emitted part in pixels on the rim of a light's image.
    pub edge_spp: u32,
    /// Skip what the scene does not need (photon maps it cannot use, shadow
    /// rays towards lights facing away); off only to check the skips.
    pub skip: bool,
    /// Progressive photon mapping's radius shrinkage (Knaus & Zwicker 2011):
    /// pass i uses r_i^2 = r_1^2 * prod_{k<i} (k + alpha - 1) / k.
    pub alpha: f32,
    /// Progressive renders: the passes after pass 0 give more camera
    /// samples to the pixels whose samples disagree in pass 0's pilot
    /// (render::adaptive). A classic render is one pass and unchanged.
    /// Off by default: at the suite's 800² it cost more passes than it
    /// saved error at 60 s (notes/progressive.md).
    pub adaptive: bool,
}

/// The defaults of every setting (the command lines show and use these).
pub const DEFAULT: Settings = Settings {
    method: Method::Photon,
    photons: 1_000_000,
    caustic_photons: 1_000_000,
    spp: 4,
    seed: 1,
    width: 800,
    height: 800,
    k_global: 100,
    k_caustic: 100,
    r_global: None,
    r_caustic: None,
    gather_rays: 4,
    aimed_gather_rays: 1,
    shadow_rays: 2,
    cache_stride: None,
    caustic_reuse: CAUSTIC_REUSE,
    edge_spp: 256,
    skip: true,
    alpha: 2.0 / 3.0,
    adaptive: false,
};

impl Settings {
    /// The gather rays aimed where a point sees anything to aim at: one at
    /// least stays cosine-distributed (the aimed ones alone would miss
    /// the rest of the hemisphere).
    pub fn aimed_rays(&self) -> u32 {
        self.aimed_gather_rays.min(self.gather_rays.saturating_sub(1))
    }
}

impl Default for Settings {
    fn default() -> Self {
        DEFAULT
    }
}

/// Photons (global and caustic) and camera samples of one pass of a
/// progressive render, where the user gives neither: many cheap passes
/// converge faster than few dear ones (notes/progressive.md).
pub const PROGRESSIVE_PHOTONS: u64 = 250_000;
pub const PROGRESSIVE_SPP: u32 = 1;

/// Caustic photons of one progressive pass and the caustic estimate's k,
/// where the user gives neither (nor `--photons`): four times the global
/// photons and four times the k, so an estimate's disk is the one that
/// 250,000 photons at k = 100 gave (the same bias) holding four times the
/// photons (a quarter of the variance). The camera pass takes most of a
/// pass and caustic photons stop at their first diffuse hit, so they are
/// the cheap part: suite scene 09-frosted-glass, 16 passes, caustic
/// window noise 0.037 -> 0.0185 for 1.38x the time a pass
/// (notes/suite.md).
pub const PROGRESSIVE_CAUSTIC_PHOTONS: u64 = 1_000_000;
pub const PROGRESSIVE_K_CAUSTIC: usize = 400;

/// Caustic photons and the caustic k of a progressive pass given no
/// counts. In a scene with media a caustic photon is not cheap: it is
/// traced on through the medium and stores volume photons on its way, so
/// four times as many doubled the pass of suite scene 13-volume-caustic
/// (100², 2 passes: 1.98 s against 0.94 s). There a pass keeps
/// [`PROGRESSIVE_PHOTONS`] at the classic k.
pub fn progressive_caustics(has_media: bool) -> (u64, usize) {
    match has_media {
        true => (PROGRESSIVE_PHOTONS, DEFAULT.k_caustic),
        false => (PROGRESSIVE_CAUSTIC_PHOTONS, PROGRESSIVE_K_CAUSTIC),
    }
}

/// Global photons per photon of the default count (`--photons` not given)
/// in a scene with media. The global volume photons are read through a
/// grid whose cost along a camera segment is the cells it crosses, not the
/// photons ([`crate::photon::volume_grid`]), so more of them cost the
/// photon pass, the maps' builds and the irradiance cache, little of the
/// camera pass: the suite's default commands at 4 times 10^6 against 10^6
/// (notes/method.md §8), 13-volume-caustic's cone window 0.0281 against
/// 0.0386 for 1.14 times the CPU time, 14-smoke's whole image 0.0101
/// against 0.0113 for 1.24 times the wall time. The caustic photons keep
/// the unscaled count; a count the user gives is taken as given.
pub const MEDIA_GLOBAL_SCALE: u64 = 4;

/// The global photons of a render whose default count is `photons`
/// (`--photons` not given): [`MEDIA_GLOBAL_SCALE`] times it with media.
pub fn default_global_photons(photons: u64, has_media: bool) -> u64 {
    match has_media {
        true => photons.saturating_mul(MEDIA_GLOBAL_SCALE),
        false => photons,
    }
}

/// Gather and shadow rays per diffuse camera vertex per ray of the
/// defaults ([`DEFAULT`]'s `gather_rays` and `shadow_rays`, neither given)
/// where photon mapping renders a scene with media. A camera sample there
/// pays for its segments in the media (their transmittance, the volume
/// photons' grid, single scattering's shadow rays) before its diffuse
/// vertex casts any ray, and splitting's best count of rays per sample
/// grows as the square root of what a sample costs without them over what
/// one ray costs. At 200 x 200, 16 spp, seeds 1 and 2, noise per render
/// squared times the camera pass's time against 4 and 2 rays: 14-smoke
/// 1.70 times less, 12-fog-shafts 1.04, 13-volume-caustic (whose noise is
/// the volume caustic's) 0.95 (notes/method.md §8). A count the user
/// gives is taken as given.
pub const MEDIA_VERTEX_RAYS_SCALE: u32 = 2;

/// The gather and shadow rays per diffuse camera vertex given neither:
/// [`MEDIA_VERTEX_RAYS_SCALE`] times the defaults where photon mapping
/// renders a scene with media.
pub fn default_vertex_rays(method: Method, has_media: bool) -> (u32, u32) {
    let scale = match method == Method::Photon && has_media {
        true => MEDIA_VERTEX_RAYS_SCALE,
        false => 1,
    };
    (DEFAULT.gather_rays * scale, DEFAULT.shadow_rays * scale)
}

/// The default [`Settings::caustic_reuse`].
pub const CAUSTIC_REUSE: f32 = 0.1;

/// Default caps on the search radius as fractions of the scene diagonal: the
/// k-nearest estimate sets the radius wherever photons are dense; the cap
/// only bounds the blur where they are sparse.
pub const GLOBAL_RADIUS_FRACTION: f32 = 0.05;
pub const CAUSTIC_RADIUS_FRACTION: f32 = 0.01;

impl Settings {
    /// The global map's radius cap in a scene of this diagonal.
    pub fn r_global(&self, diagonal: f32) -> f32 {
        self.r_global.unwrap_or(GLOBAL_RADIUS_FRACTION * diagonal)
    }

    /// The caustic map's radius cap in a scene of this diagonal.
    pub fn r_caustic(&self, diagonal: f32) -> f32 {
        self.r_caustic.unwrap_or(CAUSTIC_RADIUS_FRACTION * diagonal)
    }
}

/// Precomputed irradiance values per k-nearest estimate disk, by default.
/// Gather rays read the nearest value: the sparser the values, the further
/// the image from one with a value at every photon (test
/// `the_irradiance_cache_stays_dense_enough_as_k_shrinks`: with the k = 25
/// of late progressive passes, 6 per disk move the room's mean by 0.01%, a
/// stride of 64 by -4%).
pub const CACHE_POINTS_PER_DISK: usize = 6;

/// At least this many precomputed irradiance values where the global map
/// holds enough photons: where most photons are spent outside what the
/// camera sees (sunlight on a room's outer walls), the photons inside
/// hold fewer than k_global within the radius cap, and a value every
/// k / 6 photons left holes between them (the sun window at 2e5 photons:
/// 405 values, the image's mean +2.2%; 6,475 values, -0.15%).
pub const MIN_CACHE_POINTS: usize = 20_000;

/// The default stride: `CACHE_POINTS_PER_DISK` cached values per estimate
/// disk of `k_global` photons (16 at the default k = 100), or denser, to
/// make [`MIN_CACHE_POINTS`] of a map of `photons`.
pub fn cache_stride(k_global: usize, photons: usize) -> usize {
    (k_global / CACHE_POINTS_PER_DISK).min(photons / MIN_CACHE_POINTS).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_stride_follows_k_and_keeps_enough_points() {
        assert_eq!(cache_stride(100, 4_000_000), 16);
        assert_eq!(cache_stride(25, 4_000_000), 4);
        // A sunlit room's interior: 32,000 photons, every one cached.
        assert_eq!(cache_stride(100, 32_000), 1);
        assert_eq!(cache_stride(100, 200_000), 10);
        assert_eq!(cache_stride(100, 0), 1);
        assert_eq!(cache_stride(0, 4_000_000), 1);
    }
}
