//! Final gathering at a diffuse camera vertex in a scene with media
//! (Jensen 1996's final gather, carried through media as Jensen and
//! Christensen 1998 do). The light a diffuse vertex x reflects is split by
//! the last vertex of its light path before x that is not a mirror, glass
//! or index-matched crossing (notes/method.md §8):
//!
//! | that vertex              | estimator at x                               |
//! |--------------------------|----------------------------------------------|
//! | the light                | shadow rays (L x), the surface map (L S+ x)  |
//! | a medium vertex          | the surface map, through a cache of its own  |
//! | a glossy lobe            | the surface map, through a cache of its own  |
//! | a diffuse lobe, at y     | gather rays: cosine directions from x,      |
//! |                          | through mirrors, glass and media to y        |
//!
//! The photon pass keeps the last row's photons apart
//! ([`crate::photon::media_trace`]: `after_diffuse`), so the map read at x
//! holds only the others'. A gather ray carries the transmittance of the
//! media it crosses and what mirrors and glass let through; at y it takes
//! y's diffuse lobe times the irradiance there, read from the irradiance
//! cache of all surface photons, to which each cache point adds the
//! lights' own by shadow rays carrying the transmittance from the medium
//! its photon arrived through ([`direct_irradiance_in_media`]). Light scattered in a medium along
//! the gather ray is the surface map's at x (a medium vertex's row), so
//! the gather ray needs no beam estimate.

use super::photon::gather::GatherSequence;
use super::volpath::transmittance;
use super::volphoton::VolPhotonIntegrator;
use super::Context;
use crate::material::Transport;
use crate::math::{max_component, Color, Frame, Ray};
use crate::medium::Media;
use crate::photon::irradiance_cache::{CellRange, IrradianceCache};
use crate::sampling::{cosine_hemisphere, next_2d, stratified_2d};
use crate::scene::{Hit, Scene};
use crate::shape::Departure;
use rand::RngExt;
use std::f32::consts::PI;

/// A gather ray's events (surfaces met, crossings) are cut after this
/// many: light trapped by total internal reflection, a negligible share.
const MAX_GATHER_EVENTS: u32 = 24;

/// A gather ray's read of the irradiance cache, left until the vertex's
/// rays are all traced: which ray, what the irradiance is multiplied by
/// (the transmittance and the reflecting surface's albedo / π), where.
#[derive(Clone, Copy, Debug)]
pub struct PendingGather {
    ray: u32,
    weight: Color,
    point: glam::Vec3,
    normal: glam::Vec3,
    cell: CellRange,
}

impl VolPhotonIntegrator<'_> {
    /// Radiance a diffuse vertex `hit` (normal `n`, in medium `medium` on
    /// the side the camera path arrived from) reflects of light whose last
    /// non-specular vertex was a diffuse lobe's, over its albedo: the mean
    /// of the gather rays' radiance.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather(
        &self,
        cache: &IrradianceCache,
        hit: &Hit,
        n: glam::Vec3,
        medium: Option<u32>,
        sequence: Option<(u64, u64)>,
        pending: &mut Vec<PendingGather>,
        ctx: &mut Context,
    ) -> Color {
        let count = self.gather_rays;
        if count == 0 {
            return Color::ZERO;
        }
        let frame = Frame::from_normal(n);
        pending.clear();
        let sequence = sequence.map(|(index, scramble)| GatherSequence::new(index, scramble, count).rotated(count));
        for g in 0..count {
            let u = match &sequence {
                Some(s) => s.point(g),
                None => stratified_2d(g, count, next_2d(ctx.rng)),
            };
            let dir = frame.to_world(cosine_hemisphere(u)).normalize();
            // About a shading normal a gather ray may point into the
            // surface: it gathers nothing.
            if !(dir.dot(n) > 0.0) || (hit.shading_normal != hit.normal && !hit.leaves_as(-n, dir, true)) {
                continue;
            }
            let start = self.media.after(medium, hit.prim, hit.normal, dir);
            let (ray, dep) = hit.spawn(dir);
            self.gather_ray(cache, g, ray, dep, start, pending, ctx);
        }
        // The reads, left until every ray was traced so that their cache
        // misses overlap: first each slot (fetched since the hit), which
        // starts fetching its points, then the points. Summed ray by ray in
        // the rays' order, as they would have been at once.
        for r in pending.iter_mut() {
            r.cell = cache.locate(r.point);
        }
        let mut sum = Color::ZERO;
        let (mut ray, mut found) = (0, Color::ZERO);
        for r in pending.iter() {
            if r.ray != ray {
                sum += found;
                (ray, found) = (r.ray, Color::ZERO);
            }
            let e = self.cached_in(cache, r.point, r.normal, r.cell, ctx);
            found += r.weight * ctx.checked(e, "gather");
        }
        sum += found;
        sum / count as f32
    }

    /// Radiance arriving along one gather ray from diffuse lobes' light
    /// (see the module's table): followed through mirrors, glass and
    /// index-matched crossings, with the media's transmittance.
    #[allow(clippy::too_many_arguments)]
    fn gather_ray(
        &self,
        cache: &IrradianceCache,
        index: u32,
        mut ray: Ray,
        mut dep: Departure,
        mut medium: Option<u32>,
        pending: &mut Vec<PendingGather>,
        ctx: &mut Context,
    ) {
        let (scene, media) = (self.scene, self.media);
        let mut weight = Color::ONE;
        for _ in 0..MAX_GATHER_EVENTS {
            ctx.counters.rays += 1;
            let Some(y) = scene.intersect(&ray, Some(dep)) else { break };
            if let Some(m) = medium {
                weight *= media.get(m).transmittance(&ray, y.t, ctx.rng);
            }
            weight *= scene.transmittance(Some(dep), y.t);
            if !(max_component(weight) > 0.0) {
                break;
            }
            let material = scene.material_seen(&y, ray.dir);
            if material.is_emitter() {
                break;
            }
            let (frame, entering) = y.scattering_frame(ray.dir, &material);
            let wo = frame.to_local(-ray.dir);
            if material.diffuse_rho().is_some() {
                let rho = material.diffuse_albedo(wo);
                cache.prefetch_cell(y.point);
                pending.push(PendingGather {
                    ray: index,
                    weight: weight * rho / PI,
                    point: y.point,
                    normal: frame.n,
                    cell: CellRange::default(),
                });
            }
            // On through a mirror, glass or an index-matched crossing; a
            // glossy lobe's light is the surface map's at x.
            let branches = material.specular_branches(wo, entering, Transport::Radiance);
            let several = branches.iter().count() > 1;
            let Some(b) = branches.choose(ctx.rng) else { break };
            weight *= if several { b.scale } else { b.scale * b.prob };
            let dir = if b.wi == -wo { ray.dir } else { frame.to_world(b.wi).normalize() };
            if b.wi != -wo && y.shading_normal != y.normal && !y.leaves_as(ray.dir, dir, b.wi.z > 0.0) {
                break;
            }
            medium = media.after(medium, y.prim, y.normal, dir);
            (ray, dep) = y.spawn(dir);
        }
    }

    /// The photons' irradiance at `point` from the cache, read from a
    /// cache point no surface hides from it.
    pub(super) fn cached(&self, cache: &IrradianceCache, point: glam::Vec3, n: glam::Vec3, ctx: &mut Context) -> Color {
        self.cached_in(cache, point, n, cache.locate(point), ctx)
    }

    /// [`Self::cached`] with `point`'s cell already found.
    fn cached_in(
        &self,
        cache: &IrradianceCache,
        point: glam::Vec3,
        n: glam::Vec3,
        cell: CellRange,
        ctx: &mut Context,
    ) -> Color {
        let scene = self.scene;
        cache.lookup_seen(point, n, cell, |from, to| {
            let (dir, len) = ((to - from).normalize_or_zero(), from.distance(to));
            ctx.counters.rays += 1;
            ctx.counters.cache_rays += 1;
            let blocked = scene.occluded(&Ray::new(from, dir), None, len, None);
            ctx.counters.cache_hidden += blocked as u64;
            blocked
        })
    }
}

/// Irradiance at `x`, a point on a surface facing `n` (towards the side
/// light arrives on, where medium `medium` is), straight from the lights:
/// `count` shadow rays, each to a light drawn by power, stratified over
/// its samples, carrying the media's transmittance and what index-matched
/// surfaces let through. The surface is found by a short ray down onto it
/// (zero where there is none), as [`super::direct_irradiance`] finds it.
pub fn direct_irradiance_in_media(
    scene: &Scene,
    media: &Media,
    x: glam::Vec3,
    n: glam::Vec3,
    medium: Option<u32>,
    count: u32,
    ctx: &mut Context,
) -> Color {
    let height = 1e-4 * (1.0 + x.abs().max_element());
    let Some(hit) = scene.intersect(&Ray::new(x + height * n, -n), None) else {
        return Color::ZERO;
    };
    if hit.t > 2.0 * height || count == 0 {
        return Color::ZERO;
    }
    let mut sum = Color::ZERO;
    for s in 0..count {
        let Some((index, chance)) = scene.pick_light_index(ctx.rng.random::<f32>()) else { return Color::ZERO };
        let light = &scene.lights[index];
        let Some(inc) = light.sample_li(hit.point, n, stratified_2d(s, count, next_2d(ctx.rng))) else { continue };
        let cos = inc.dir.dot(n);
        if !(cos > 0.0) || inc.intensity == Color::ZERO {
            continue;
        }
        if hit.shading_normal != hit.normal && !hit.leaves_as(-n, inc.dir, true) {
            continue;
        }
        let (shadow, dep) = hit.spawn(inc.dir);
        let reach = inc.target.map_or(f32::INFINITY, |y| (y - shadow.origin).length());
        let start = media.after(medium, hit.prim, hit.normal, inc.dir);
        let tr = transmittance(scene, media, shadow, Some(dep), reach, inc.prim, start, ctx);
        sum += inc.intensity * tr * (cos / chance);
    }
    sum / count as f32
}
