//! Warps from the unit square to the shapes the renderer samples, each next
//! to its pdf so the two cannot drift apart; and the random streams, keyed by
//! work-item indices (pixel, photon) and never by thread, so an image does not
//! depend on how rayon schedules work.

use glam::{Vec2, Vec3};
use rand::RngExt;
use rand_pcg::Pcg32;
use std::f32::consts::{FRAC_PI_4, PI};

/// The generator every stream uses (named, so its algorithm cannot change
/// under us the way `SmallRng`'s may).
pub type Rng = Pcg32;

/// SplitMix64 finaliser: decorrelates sequential indices before they seed PCG.
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// Domains keep the camera pass, the global photon pass and the caustic photon
/// pass on disjoint streams even when their indices coincide.
#[derive(Clone, Copy, Debug)]
#[repr(u64)]
pub enum Domain {
    Camera = 0x00C4_3E8A,
    GlobalPhotons = 0x0061_0B41,
    CausticPhotons = 0x00CA_05C1,
    EdgeProbes = 0x00ED_6E00,
}

/// The random stream of work item `index` in `domain` for run `seed`.
pub fn stream(seed: u64, domain: Domain, index: u64) -> Rng {
    let state = splitmix64(seed ^ splitmix64(domain as u64));
    Pcg32::new(state, splitmix64(index))
}

/// A uniform sample in [0, 1)^2.
pub fn next_2d(rng: &mut Rng) -> Vec2 {
    Vec2::new(rng.random::<f32>(), rng.random::<f32>())
}

/// Shirley–Chiu concentric map: uniform on the unit disk, preserves strata.
/// pdf with respect to area: 1 / pi.
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, std::f32::consts::FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction on the hemisphere around local +z (Malley).
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// pdf of [`cosine_hemisphere`] per unit solid angle, for local direction `w`.
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    w.z.max(0.0) / PI
}

/// Uniform direction inside the cone around local +z with half-angle
/// `acos(cos_max)`; `cos_max` in [-1, 1), -1 being the whole sphere.
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_t = 1.0 - u.x * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// pdf of [`uniform_cone`] per unit solid angle (inside the cone).
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// The `index`-th of `n` jittered strata of [0,1)^2 (an `m x m` grid when `n`
/// is a square; otherwise `n` strata along a line, still jittered).
pub fn stratified_2d(index: u32, n: u32, u: Vec2) -> Vec2 {
    let m = (n as f32).sqrt() as u32;
    if m * m == n {
        let (ix, iy) = (index % m, index / m);
        Vec2::new((ix as f32 + u.x) / m as f32, (iy as f32 + u.y) / m as f32)
    } else {
        Vec2::new((index as f32 + u.x) / n as f32, u.y)
    }
    .min(Vec2::splat(1.0 - f32::EPSILON * 0.5))
}
