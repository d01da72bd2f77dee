//! The photon pass of a scene with participating media (Jensen and
//! Christensen 1998): photons fly freely through media (delta tracking in
//! heterogeneous ones, exactly in homogeneous ones:
//! [`crate::medium::Medium::sample_flight`]), scatter by the phase function
//! with the albedo as their chance of going on, cross index-matched
//! surfaces unchanged, and are stored where they scatter in a medium (the
//! volume maps, [`super::volume_map`]) and where they land on a diffuse
//! surface. Each pass stores what the camera pass reads from it and
//! nothing that another estimator counts (notes/method.md §8):
//!
//! * the **global pass** stores photons whose path so far holds a diffuse,
//!   glossy or medium vertex (L (S|D|V)* (D|V) (S|D|V)* stored): not light
//!   straight from a light (shadow rays count it), not light only through
//!   mirrors and glass (the caustic pass counts it);
//! * the **caustic pass** aims photons at mirror and glass objects and
//!   stores only light → specular+ → (diffuse surface | medium): surface
//!   caustics and volume caustics, each path at its first non-specular
//!   vertex.
//!
//! Surface photons whose last vertex other than a mirror, glass or
//! index-matched crossing was a diffuse lobe's are kept apart
//! (`after_diffuse`): final gathering from a diffuse camera vertex counts
//! their paths, the rest are read there directly.
//!
//! As in [`super::trace`], every photon draws from its own random stream
//! and blocks are kept in order: the same photons on any number of threads.

use super::aims::Target;
use super::guide::{EmissionGuide, Stored};
use super::trace::{emit_at, photons_to_emit, Pass};
use super::volume_map::VolumePhoton;
use super::Photon;
use crate::material::{Lobe, Transport};
use crate::math::{max_component, Color, Ray};
use crate::medium::{Flight, Media};
use crate::sampling::{next_2d, stream, Domain, Rng};
use crate::scene::Scene;
use crate::shape::Departure;
use rand::RngExt;
use rayon::prelude::*;

/// Photons per block (one rayon task).
const BLOCK: u64 = 4096;
/// A photon's events (scatterings, crossings) are cut after this many.
const MAX_EVENTS: u32 = 256;
/// Surfaces crossed looking for the medium a light sits in.
const MAX_PROBE: u32 = 64;

/// What a pass through a scene with media stored.
#[derive(Debug, Default)]
pub struct MediaPhotons {
    /// Surface photons after a medium vertex, a glossy lobe, or only
    /// mirrors and glass.
    pub surface: Vec<Photon>,
    /// Surface photons whose last vertex but specular ones was a diffuse
    /// lobe's.
    pub after_diffuse: Vec<Photon>,
    pub volume: Vec<VolumePhoton>,
    pub emitted: u64,
    pub rays: u64,
}

/// Traces `n` photons of `pass` through the scene and its `media`.
pub fn trace_media_pass(
    scene: &Scene,
    media: &Media,
    targets: &[Target],
    pass: Pass,
    n: u64,
    seed: u64,
    on_block: &(dyn Fn(u64) + Sync),
) -> MediaPhotons {
    let emits = max_component(scene.emitted_power()) > 0.0;
    if n == 0 || !emits || (pass == Pass::Caustic && targets.is_empty()) {
        return MediaPhotons { emitted: n, ..Default::default() };
    }
    let domain = match pass {
        Pass::Global => Domain::GlobalPhotons,
        Pass::Caustic => Domain::CausticPhotons,
    };
    // As the pass of a scene without media does: light at infinity sends
    // its photons where the camera sees their light (in media too), and
    // the pass emits as many as make n count.
    let guide = match pass {
        Pass::Global => EmissionGuide::build(scene, true, seed, &|ray, departure, power, rng| {
            pilot_photon(scene, media, ray, departure, power, rng)
        }),
        Pass::Caustic => None,
    };
    let asked = n;
    let n = match pass {
        Pass::Global => photons_to_emit(scene, n, guide.as_ref(), seed),
        Pass::Caustic => n,
    };
    let blocks: Vec<MediaPhotons> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let mut out = MediaPhotons::default();
            for i in b * BLOCK..((b + 1) * BLOCK).min(n) {
                let mut rng = stream(seed, domain, i);
                if let (_, Some((ray, departure, power))) =
                    emit_at(scene, targets, pass, n, None, guide.as_ref(), &mut rng)
                {
                    out.rays += trace_photon(scene, media, pass, ray, departure, power, &mut rng, &mut out);
                }
            }
            let asked_by = |i: u64| (i as u128 * asked as u128 / n as u128) as u64;
            on_block(asked_by(((b + 1) * BLOCK).min(n)) - asked_by(b * BLOCK));
            out
        })
        .collect();
    let mut all = MediaPhotons { emitted: n, ..Default::default() };
    for b in blocks {
        all.surface.extend(b.surface);
        all.after_diffuse.extend(b.after_diffuse);
        all.volume.extend(b.volume);
        all.rays += b.rays;
    }
    all
}

/// Follows one pilot photon of the global pass ([`EmissionGuide`]) as the
/// pass would, and returns where it stored photons.
fn pilot_photon(
    scene: &Scene,
    media: &Media,
    ray: Ray,
    departure: Option<Departure>,
    power: Color,
    rng: &mut Rng,
) -> Stored {
    let mut out = MediaPhotons::default();
    trace_photon(scene, media, Pass::Global, ray, departure, power, rng, &mut out);
    let surface = out.surface.iter().chain(&out.after_diffuse).map(|p| (p.position(), Some(p.surface_normal())));
    surface.chain(out.volume.iter().map(|p| (p.pos, None))).collect()
}

/// Follows one photon, storing into `out`; returns the rays it cast.
#[allow(clippy::too_many_arguments)]
fn trace_photon(
    scene: &Scene,
    media: &Media,
    pass: Pass,
    mut ray: Ray,
    mut departure: Option<Departure>,
    mut power: Color,
    rng: &mut Rng,
    out: &mut MediaPhotons,
) -> u64 {
    let (mut medium, mut rays) = start_medium(scene, media, &ray, departure);
    if let Some(m) = medium.filter(|_| from_infinity(scene, ray.origin)) {
        // Light from infinity crossed the medium it starts in all the
        // way from there: as a shadow ray towards it leaving the scene in
        // that medium sees it (none through a homogeneous fog).
        power *= media.get(m).transmittance(&Ray::new(ray.origin, -ray.dir), f32::INFINITY, rng);
        if !(max_component(power) > 0.0) {
            return rays;
        }
    }
    // Specular vertices so far, and whether there was nothing else.
    let (mut specular, mut only_specular) = (0u32, true);
    // Whether the last vertex but specular ones was a diffuse lobe's.
    let mut after_diffuse = false;
    for _ in 0..MAX_EVENTS {
        rays += 1;
        let hit = scene.intersect(&ray, departure);
        let t_surface = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
        if let Some(m) = medium {
            let med = media.get(m);
            match med.sample_flight(&ray, t_surface, power, rng) {
                Flight::Passed { weight } => power *= weight,
                Flight::Scattered { t, weight } => {
                    power *= weight;
                    let p = ray.at(t);
                    let store = match pass {
                        Pass::Global => !only_specular,
                        Pass::Caustic => specular > 0,
                    };
                    if store && max_component(power) > 0.0 && power.is_finite() {
                        out.volume.push(VolumePhoton::new(p, power, ray.dir, m));
                    }
                    if pass == Pass::Caustic {
                        return rays;
                    }
                    only_specular = false;
                    after_diffuse = false;
                    // The albedo (the collision's weight) is the chance
                    // to go on; survivors carry their power before it.
                    let q = max_component(weight).min(1.0);
                    if !(rng.random::<f32>() < q) {
                        return rays;
                    }
                    power /= q;
                    let (dir, _) = med.phase.sample(ray.dir, next_2d(rng));
                    (ray, departure) = (Ray::new(p, dir), None);
                    continue;
                }
            }
        }
        let Some(hit) = hit else { return rays };
        power *= scene.transmittance(departure, hit.t);
        let material = &scene.material_seen(&hit, ray.dir);
        let (frame, entering) = hit.scattering_frame(ray.dir, material);
        if scene.stores_photons(&hit, material) {
            let store = match pass {
                Pass::Global => !only_specular,
                Pass::Caustic => specular > 0,
            };
            if store && max_component(power) > 0.0 {
                let photon = with_medium(Photon::new(hit.point, power, frame.n), medium);
                match after_diffuse {
                    true => out.after_diffuse.push(photon),
                    false => out.surface.push(photon),
                }
            }
        }
        let wo = frame.to_local(-ray.dir);
        let p = material.photon_survival(wo);
        if p < 1.0 && !(rng.random::<f32>() < p) {
            return rays;
        }
        let Some(scatter) = material.sample(wo, entering, Transport::Importance, rng) else { return rays };
        if scatter.lobe == Lobe::Specular && scatter.wi == -wo {
            // An index-matched crossing: the same flight goes on beyond.
            power *= scatter.weight / p;
            medium = media.after(medium, hit.prim, hit.normal, ray.dir);
            let (next, dep) = hit.spawn(ray.dir);
            (ray, departure) = (next, Some(dep));
            continue;
        }
        let dir = frame.to_world(scatter.wi).normalize();
        let smooth = hit.shading_normal != hit.normal;
        if smooth && !hit.leaves_as(ray.dir, dir, scatter.wi.z > 0.0) {
            return rays;
        }
        let is_specular = match scatter.lobe {
            Lobe::Specular => true,
            Lobe::Diffuse => false,
            Lobe::Glossy => material.glossy().is_some_and(|g| g.carries_caustics()),
        };
        match is_specular {
            true => specular += 1,
            false if pass == Pass::Caustic => return rays,
            false => only_specular = false,
        }
        if scatter.lobe != Lobe::Specular {
            after_diffuse = scatter.lobe == Lobe::Diffuse;
        }
        power *= scatter.weight / p;
        if smooth {
            power *= hit.adjoint_correction(-ray.dir, dir);
        }
        if !(max_component(power) > 0.0) {
            return rays;
        }
        medium = media.after(medium, hit.prim, hit.normal, dir);
        let (next, dep) = hit.spawn(dir);
        (ray, departure) = (next, Some(dep));
    }
    rays
}

/// The most media a scene may have for its surface photons to say which
/// medium they arrived through ([`medium_of`]).
pub const MAX_NAMED_MEDIA: usize = 254;

/// `photon`, marked with the medium it arrived through (in the fourth
/// byte of its normal, which nothing else reads): 0 for none, else the
/// medium's index plus one; 0 too past [`MAX_NAMED_MEDIA`].
fn with_medium(mut photon: Photon, medium: Option<u32>) -> Photon {
    let code = medium.filter(|&m| (m as usize) < MAX_NAMED_MEDIA).map_or(0, |m| m + 1);
    photon.normal[3] = code as u8 as i8;
    photon
}

/// The medium on the side of its surface that a surface photon of a scene
/// with at most [`MAX_NAMED_MEDIA`] media arrived from.
pub fn medium_of(photon: &Photon) -> Option<u32> {
    (photon.normal[3] as u8 as u32).checked_sub(1)
}

/// Whether a photon starting at `origin` comes from a light at infinity:
/// those start outside the scene's bounds, which hold every other light
/// ([`crate::light::place_lights`]).
fn from_infinity(scene: &Scene, origin: glam::Vec3) -> bool {
    let (lo, hi) = scene.bounds();
    let margin = glam::Vec3::splat(1e-3 * scene.diagonal());
    !(origin.cmpge(lo - margin).all() && origin.cmple(hi + margin).all())
}

/// The medium a photon leaving its light along `ray` starts in: the side
/// of its light's surface it leaves towards where that surface bounds
/// media; else the side of the first surface that bounds media it would
/// cross (found by a probe that passes through every surface); where
/// there is none, the camera's (a medium that fills the scene, named only
/// by the camera, as camera paths and their shadow rays see it). Also the
/// probe's rays.
fn start_medium(scene: &Scene, media: &Media, ray: &Ray, departure: Option<Departure>) -> (Option<u32>, u64) {
    if let Some(i) = departure.and_then(|d| media.interface(d.prim).map(|i| (d, i))).map(|(d, i)| {
        if d.outward {
            i.exterior
        } else {
            i.interior
        }
    }) {
        return (i, 0);
    }
    let (mut probe, mut dep) = (*ray, departure);
    for k in 0..MAX_PROBE {
        let Some(hit) = scene.intersect(&probe, dep) else { return (media.camera, k as u64 + 1) };
        if let Some(i) = media.interface(hit.prim) {
            let inside = probe.dir.dot(hit.normal) > 0.0;
            return (if inside { i.interior } else { i.exterior }, k as u64 + 1);
        }
        let (next, d) = hit.spawn(probe.dir);
        (probe, dep) = (next, Some(d));
    }
    (media.camera, MAX_PROBE as u64)
}
