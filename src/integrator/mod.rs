//! Integrators: turn a camera ray into radiance.
//!
//! * [`photon`]: Jensen's photon-mapping estimator (classic and progressive);
//! * [`path`]: path tracing with next-event estimation, the unbiased reference.
//!
//! Both share the camera pass (`render`), direct lighting and the dielectric.

pub mod path;
pub mod photon;
pub mod whitted;

use crate::math::{Color, Frame, Ray};
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::photon::irradiance_cache::CellRange;
use crate::photon::map::Scratch;
use crate::sampling::{next_2d, stratified_2d, Rng};
use crate::scene::{Hit, Scene};
use glam::Vec3;

/// Which part of the radiance a camera sample estimates. A pixel's value is
/// the sum of what reaches the eye from a light's own surface (directly or
/// through mirrors and glass: paths E S* L) and everything else; the two can
/// be estimated with different numbers of samples, because the first is
/// cheap and, at the rim of a light's image, has most of the variance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    All,
    /// Emitted radiance seen along specular chains only (diffuse hits are dark).
    Emitted,
    /// Everything but the emitted part.
    Reflected,
}

/// A camera-ray estimator.
pub trait Integrator: Sync {
    /// Radiance arriving along a camera ray (towards its origin), less what
    /// it left in `ctx.pending` (none where that is `None`).
    fn radiance(&self, ray: Ray, part: Part, ctx: &mut Context) -> Color;

    /// The radiance of the reads [`Self::radiance`] left in `ctx.pending`,
    /// which it empties.
    fn resolve(&self, ctx: &mut Context) -> Color {
        if let Some(pending) = ctx.pending.as_deref_mut() {
            pending.clear();
        }
        Color::ZERO
    }
}

/// A read of precomputed irradiance that a camera sample leaves for later:
/// the camera pass resolves a pixel's reads together, so that their cache
/// misses overlap instead of following one another (final gathering's
/// reads land anywhere in the scene).
#[derive(Clone, Copy, Debug, Default)]
pub struct PendingRead {
    pub point: Vec3,
    pub normal: Vec3,
    /// What the irradiance there is multiplied by on its way to the camera.
    pub weight: Color,
    pub cell: CellRange,
}

/// Per-thread state: random stream, scratch for lookups, counters, and
/// what the pixel's earlier samples left for its later ones.
pub struct Context<'r> {
    pub rng: &'r mut Rng,
    pub scratch: &'r mut Scratch,
    pub tally: &'r mut Tally,
    pub pixel: u64,
    pub memo: &'r mut PixelMemo,
    /// Where reads may be left for [`Integrator::resolve`]; `None`: made
    /// at once.
    pub pending: Option<&'r mut Vec<PendingRead>>,
}

/// What one pixel's samples share, and only they: it starts empty at every
/// pixel, so a pixel's value never depends on which thread rendered it or
/// on the pixels before.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelMemo {
    /// The pixel's last caustic estimate: where it was made, on what
    /// surface, and how far from there it may stand in for a new one.
    pub caustic: Option<CausticMemo>,
}

#[derive(Clone, Copy, Debug)]
pub struct CausticMemo {
    pub point: Vec3,
    pub normal: Vec3,
    pub reach2: f32,
    pub estimate: crate::photon::map::ConeEstimate,
}

impl<'r> Context<'r> {
    pub fn new(
        rng: &'r mut Rng,
        scratch: &'r mut Scratch,
        tally: &'r mut Tally,
        pixel: u64,
        memo: &'r mut PixelMemo,
        pending: Option<&'r mut Vec<PendingRead>>,
    ) -> Self {
        Context { rng, scratch, tally, pixel, memo, pending }
    }
    /// Passes a finite estimate through; counts and drops a non-finite one,
    /// remembering the first (pixel, estimator). Debug builds stop there.
    pub fn checked(&mut self, c: Color, estimator: &'static str) -> Color {
        debug_assert!(c.is_finite(), "{estimator} estimate {c} at pixel {}", self.pixel);
        if c.is_finite() {
            c
        } else {
            self.tally.nonfinite += 1;
            self.tally.first_nonfinite.get_or_insert((self.pixel, estimator));
            Color::ZERO
        }
    }
}

/// What a thread counted while it shaded: rays cast, and samples whose
/// radiance came out non-finite (a bug at some estimator; never written).
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally {
    pub rays: u64,
    pub nonfinite: u64,
    /// Pixels given extra samples on the rim of a light's image.
    pub edge_pixels: usize,
    /// Shadow rays not cast: the light's back faced the point.
    pub shadow_rays_skipped: u64,
    /// Caustic estimates made, and those a pixel's earlier sample answered.
    pub caustic_estimates: u64,
    pub caustic_reused: u64,
    /// First non-finite sample seen: (pixel index, estimator name).
    pub first_nonfinite: Option<(u64, &'static str)>,
}

impl Tally {
    pub fn merge(mut self, other: Tally) -> Tally {
        self.rays += other.rays;
        self.nonfinite += other.nonfinite;
        self.edge_pixels += other.edge_pixels;
        self.shadow_rays_skipped += other.shadow_rays_skipped;
        self.caustic_estimates += other.caustic_estimates;
        self.caustic_reused += other.caustic_reused;
        self.first_nonfinite = match (self.first_nonfinite, other.first_nonfinite) {
            (Some(a), Some(b)) => Some(if a.0 <= b.0 { a } else { b }),
            (a, b) => a.or(b),
        };
        self
    }
}

/// Light reflected at a surface point straight from the lights:
/// sum over lights of f(w) I cos_x, averaged over `count` stratified samples
/// of each area light (one sample of a point or directional light is exact),
/// each with a shadow ray. `brdf(w)` is the BRDF for light arriving from
/// unit `w` (towards the light); `n` is the normal on the viewer's side.
/// With `skip`, a light whose emitting side faces away from the point (a
/// one-sided area light seen from behind or edge-on, where every sample has
/// cos_l <= 0) is not sampled.
#[allow(clippy::too_many_arguments)]
pub fn direct_light(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    brdf: impl Fn(Vec3) -> Color,
    count: u32,
    skip: bool,
    ctx: &mut Context,
) -> Color {
    let mut sum = Color::ZERO;
    for light in &scene.lights {
        let count = if light.is_delta() { 1 } else { count };
        if skip && light.faces_away(hit.point) {
            ctx.tally.shadow_rays_skipped += count as u64;
            continue;
        }
        let mut light_sum = Color::ZERO;
        // Samples two at a time: both are drawn before either shadow ray
        // is cast, so the processor works out the second (a chain of a
        // division, a square root and another division) while the first
        // ray is traced. The random numbers are drawn in the same order.
        for s in (0..count).step_by(2) {
            let mut pair = [None; 2];
            for (j, slot) in pair.iter_mut().enumerate().take((count - s) as usize) {
                let u = stratified_2d(s + j as u32, count, next_2d(ctx.rng));
                *slot = light.incident(hit.point, u).map(|inc| (n.dot(inc.dir), inc)).filter(|&(c, _)| c > 0.0);
            }
            for (cos_x, inc) in pair.into_iter().flatten() {
                let (shadow, dep) = hit.spawn(inc.dir);
                ctx.tally.rays += 1;
                let t_max = inc.target.map_or(f32::INFINITY, |p| (p - shadow.origin).length());
                if !scene.occluded(&shadow, Some(dep), t_max, inc.prim) {
                    light_sum += brdf(inc.dir) * inc.intensity * cos_x;
                }
            }
        }
        sum += light_sum / count.max(1) as f32;
    }
    sum
}

/// The two directions leaving a smooth dielectric, computed in the local
/// frame of the surface.
pub struct GlassBranches {
    pub fresnel: f32,
    pub reflected: Vec3,
    /// Refracted direction and the radiance scale (n_i / n_t)^2 of a camera
    /// path crossing into the other medium; `None` on total internal reflection.
    pub refracted: Option<(Vec3, f32)>,
}

#[inline]
pub fn glass_branches(hit: &Hit, ray: &Ray, ior: f32) -> GlassBranches {
    let frame = Frame::from_normal(hit.facing_normal(ray.dir));
    let wi = frame.to_local(-ray.dir);
    let entering = ray.dir.dot(hit.normal) < 0.0;
    let (n_i, n_t) = if entering { (1.0, ior) } else { (ior, 1.0) };
    let fresnel = fresnel_dielectric(wi.z, n_i, n_t);
    let reflected = frame.to_world(reflect(wi)).normalize();
    let refracted = refract(wi, n_i / n_t).map(|wt| (frame.to_world(wt).normalize(), (n_i / n_t).powi(2)));
    GlassBranches { fresnel: if refracted.is_some() { fresnel } else { 1.0 }, reflected, refracted }
}
