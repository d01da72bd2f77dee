//! Path tracing through participating media: the path tracer of a scene
//! that has media ([`super::path::PathIntegrator`] hands such scenes
//! here), solving the radiative transfer equation as Mitsuba 3's `volpath`
//! integrator does (src/integrators/volpath.cpp), so that both render the
//! same image:
//!
//! * a ray in a medium draws a free flight ([`crate::medium::Medium::sample_flight`]):
//!   it scatters there, by the phase function, or reaches the next surface;
//! * a surface that lets light straight through (Mitsuba's `null` BSDF, a
//!   mask's open part, a thin pane's transmission) is an index-matched
//!   boundary: the ray goes on unchanged, and the crossing is no vertex
//!   of the path (it counts nothing towards `max_depth`);
//! * crossing a shape with media bound to it puts the ray in the medium on
//!   the side it leaves towards ([`crate::medium::Media::after`]);
//! * at every scattering vertex (in a medium, or a surface with a diffuse
//!   or glossy lobe) one light, drawn by power, is sampled with a shadow
//!   ray that carries the transmittance of the media and of the
//!   index-matched surfaces it crosses (and stops at any other surface),
//!   and is combined with the light the next direction meets by multiple
//!   importance sampling (power heuristic); after a specular vertex the
//!   light met is counted in full.
//!
//! A path's length is counted as Mitsuba counts it: scattering vertices
//! (in media and on surfaces), not index-matched crossings.
//!
//! The emitted part ([`Part::Emitted`], which the camera pass samples more
//! at the rims of lights' images) is [`emitted_part`]'s.

use super::mis::power_heuristic;
use super::path::PathIntegrator;
use super::photon::gather::GatherSequence;
use super::{Context, Part};
use crate::light::{Incident, Light};
use crate::material::{Branch, Lobe, Material, Transport};
use crate::math::{max_component, Color, Frame, Ray};
use crate::medium::{Flight, Media, Phase};
use crate::sampling::next_2d;
use crate::scene::{Hit, Scene};
use crate::shape::Departure;
use glam::Vec3;
use rand::RngExt;
use std::f32::consts::PI;

/// Russian roulette starts after this many scattering vertices.
const RR_DEPTH: u32 = 3;
/// Hard cap on the events of a path (scatterings and crossings).
const MAX_EVENTS: u32 = 1024;
/// Hard cap on the surfaces a shadow ray crosses.
const MAX_CROSSINGS: u32 = 256;

/// Where the path last scattered with a density the lights' sampling
/// shares (a smooth lobe, or a phase function): what the light met next
/// needs for its MIS weight.
#[derive(Clone, Copy, Debug)]
struct Scattered {
    point: Vec3,
    /// The surface's normal on the side its shadow rays were sampled
    /// about; `None` in a medium (lights sampled over the whole sphere).
    normal: Option<Vec3>,
    /// The density with which the next direction was drawn.
    pdf: f32,
}

pub(super) fn radiance(pt: &PathIntegrator, media: &Media, ray: Ray, part: Part, ctx: &mut Context) -> Color {
    let scene = pt.scene;
    if part == Part::Emitted {
        return emitted_part(scene, media, ray, ctx);
    }
    let limits = scene.paths;
    let within = |vertices: u32| limits.max_depth.is_none_or(|m| vertices <= m);
    let mut radiance = Color::ZERO;
    let mut throughput = Color::ONE;
    let (mut ray, mut departure): (Ray, Option<Departure>) = (ray, None);
    let mut medium = media.camera;
    // Scattering vertices so far (index-matched crossings are none).
    let mut vertices = 0u32;
    // Whether every vertex so far was specular: light met is E S* L.
    let mut specular_chain = true;
    // Whether light met now is counted in full (after the eye, a specular
    // vertex, or a medium that casts no shadow rays); else with its MIS
    // weight against `last`.
    let mut count_full = true;
    let mut last: Option<Scattered> = None;
    for _ in 0..MAX_EVENTS {
        if !within(vertices + 1) {
            break;
        }
        ctx.counters.rays += 1;
        let med = medium.map(|m| media.get(m));
        // In a homogeneous medium the flight is drawn first, and a surface
        // sought only closer than it (in fog most flights end in it).
        let drawn = med.filter(|m| m.is_homogeneous() && m.scatters());
        let distance = drawn.map(|m| m.draw_distance(throughput, ctx.rng));
        let hit = scene.intersect_within(&ray, departure, distance.map_or(f32::INFINITY, |d| d.t));
        let t_surface = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
        if let Some(med) = med {
            let flight = match (drawn, &distance) {
                (Some(m), Some(d)) if hit.is_none() && d.t.is_finite() => {
                    Flight::Scattered { t: d.t, weight: m.scattered_at(d, ray.at(d.t)) }
                }
                (Some(m), Some(d)) => Flight::Passed { weight: m.passed(d, t_surface) },
                _ => med.sample_flight(&ray, t_surface, throughput, ctx.rng),
            };
            match flight {
                Flight::Passed { weight } => throughput *= weight,
                Flight::Scattered { t, weight } => {
                    throughput *= weight;
                    vertices += 1;
                    // Nothing beyond this vertex fits the path's length.
                    if !within(vertices + 1) || max_component(throughput) <= 0.0 {
                        break;
                    }
                    let p = ray.at(t);
                    let phase = med.phase;
                    if med.sample_emitters {
                        let direct = medium_light(scene, media, p, ray.dir, phase, medium, ctx);
                        radiance += throughput * ctx.checked(direct, "volpath medium light");
                    }
                    let (dir, pdf) = phase.sample(ray.dir, next_2d(ctx.rng));
                    last = Some(Scattered { point: p, normal: None, pdf });
                    count_full = !med.sample_emitters;
                    specular_chain = false;
                    (ray, departure) = (Ray::new(p, dir), None);
                    if !roulette(&mut throughput, vertices, ctx) {
                        break;
                    }
                    continue;
                }
            }
            if max_component(throughput) <= 0.0 {
                break;
            }
        }
        let wanted = match part {
            Part::All => true,
            Part::Reflected => !specular_chain,
            Part::Emitted => unreachable!("the emitted part is emitted_part's"),
        };
        let hidden = vertices == 0 && limits.hide_emitters;
        let Some(hit) = hit else {
            if wanted && !hidden {
                let sky = if count_full {
                    scene.background(ray.dir)
                } else {
                    last.map_or(Color::ZERO, |s| from_infinity(scene, &s, ray.dir))
                };
                radiance += throughput * sky;
            }
            break;
        };
        if wanted && !hidden {
            let le = scene.emitted(&hit, ray.dir);
            if le != Color::ZERO {
                let w = if count_full { 1.0 } else { last.map_or(0.0, |s| emitted_weight(scene, &s, &hit)) };
                radiance += throughput * le * w;
            }
        }
        let material = scene.material_seen(&hit, ray.dir);
        if material.is_emitter() {
            break;
        }
        let (frame, entering) = hit.scattering_frame(ray.dir, &material);
        let n = frame.n;
        let wo = frame.to_local(-ray.dir);
        let Some(scatter) = material.sample(wo, entering, Transport::Radiance, ctx.rng) else { break };
        if scatter.lobe == Lobe::Specular && scatter.wi == -wo {
            // Straight through an index-matched surface: the same ray
            // goes on, in the medium beyond.
            throughput *= scatter.weight;
            medium = media.after(medium, hit.prim, hit.normal, ray.dir);
            let (next, dep) = hit.spawn(ray.dir);
            (ray, departure) = (next, Some(dep));
            if max_component(throughput) <= 0.0 {
                break;
            }
            continue;
        }
        // A scattering vertex: its light, then its continuation.
        vertices += 1;
        let smooth = scatter.lobe != Lobe::Specular;
        if material.has_smooth_lobes() && within(vertices + 1) {
            let direct = surface_light(scene, media, &hit, &material, &frame, wo, entering, medium, true, 1, None, ctx);
            radiance += throughput * ctx.checked(direct, "volpath surface light");
        }
        let dir = frame.to_world(scatter.wi).normalize();
        if hit.shading_normal != hit.normal && !hit.leaves_as(ray.dir, dir, scatter.wi.z > 0.0) {
            break;
        }
        if smooth {
            let pdf = material.pdf(wo, scatter.wi, entering);
            last = Some(Scattered { point: hit.point, normal: Some(n), pdf });
            count_full = false;
            specular_chain = false;
        } else {
            last = None;
            count_full = true;
        }
        throughput *= scatter.weight;
        medium = media.after(medium, hit.prim, hit.normal, dir);
        let (next, dep) = hit.spawn(dir);
        (ray, departure) = (next, Some(dep));
        if !roulette(&mut throughput, vertices, ctx) {
            break;
        }
    }
    radiance
}

/// The emitted part ([`Part::Emitted`]): light reached from the eye along
/// specular chains (mirrors, glass, index-matched crossings) through vacuum
/// or media, carrying their transmittance: the light that reaches the eye
/// unscattered. Through thin fog a light's image stays sharp (only dimmer),
/// and its rim is most of the pixels' noise there, as in vacuum; the glow
/// about it (light scattered in the medium) is the reflected part's.
///
/// At the first [`SPLITS`] vertices with two branches (glass: reflection
/// and refraction) both are followed, each weighted by its share, so a
/// sample is the exact Fresnel-weighted sum over them. Choosing one by
/// its share left a light seen through a rare branch as samples of 0 or
/// of its full radiance: in suite scene 13 the ceiling's light seen in
/// the glass ball after an internal reflection (a share of about 8%, a
/// band of pixels reading 15 where one sample read 0 or 198) held most of
/// the image's squared error, and its pixels' four probes saw it too
/// seldom for them all to be taken as rims.
pub(super) fn emitted_part(scene: &Scene, media: &Media, ray: Ray, ctx: &mut Context) -> Color {
    emitted_along(scene, media, Chain::from_eye(ray, media, SPLITS), ctx)
}

/// Vertices with two specular branches at which [`emitted_part`] follows
/// both (at most 2^`SPLITS` chains a sample); beyond them one is chosen.
const SPLITS: u32 = 4;

/// Where a specular chain of the emitted part stands.
#[derive(Clone, Copy)]
struct Chain {
    ray: Ray,
    departure: Option<Departure>,
    medium: Option<u32>,
    throughput: Color,
    /// Specular vertices so far (crossings are none), and how many more
    /// with two branches follow both.
    vertices: u32,
    splits_left: u32,
}

impl Chain {
    fn from_eye(ray: Ray, media: &Media, splits_left: u32) -> Chain {
        Chain { ray, departure: None, medium: media.camera, throughput: Color::ONE, vertices: 0, splits_left }
    }
}

/// The light [`emitted_part`] meets along `chain` and the branches after it.
fn emitted_along(scene: &Scene, media: &Media, mut chain: Chain, ctx: &mut Context) -> Color {
    let limits = scene.paths;
    let within = |vertices: u32| limits.max_depth.is_none_or(|m| vertices <= m);
    let mut radiance = Color::ZERO;
    for _ in 0..MAX_EVENTS {
        let med = chain.medium.map(|m| media.get(m));
        if !within(chain.vertices + 1) {
            break;
        }
        ctx.counters.rays += 1;
        let ray = chain.ray;
        let hit = scene.intersect(&ray, chain.departure);
        if let Some(m) = med {
            chain.throughput *= m.transmittance(&ray, hit.as_ref().map_or(f32::INFINITY, |h| h.t), ctx.rng);
        }
        let hidden = chain.vertices == 0 && limits.hide_emitters;
        let Some(hit) = hit else {
            if !hidden {
                radiance += chain.throughput * scene.background(ray.dir);
            }
            break;
        };
        if !hidden {
            radiance += chain.throughput * scene.emitted(&hit, ray.dir);
        }
        let material = scene.material_seen(&hit, ray.dir);
        if material.is_emitter() {
            break;
        }
        let (frame, entering) = hit.scattering_frame(ray.dir, &material);
        let wo = frame.to_local(-ray.dir);
        let branches = material.specular_branches(wo, entering, Transport::Radiance);
        // Where the chain follows the branch: its direction, or None where
        // a shading normal sends it back through the surface.
        let follow = |b: &Branch, mut next: Chain| {
            let straight = b.wi == -wo;
            let dir = if straight { ray.dir } else { frame.to_world(b.wi).normalize() };
            if !straight && hit.shading_normal != hit.normal && !hit.leaves_as(ray.dir, dir, b.wi.z > 0.0) {
                return None;
            }
            next.vertices += (!straight) as u32;
            next.medium = media.after(chain.medium, hit.prim, hit.normal, dir);
            let (r, dep) = hit.spawn(dir);
            (next.ray, next.departure) = (r, Some(dep));
            Some(next)
        };
        if chain.splits_left > 0 && branches.iter().count() > 1 {
            let split = Chain { splits_left: chain.splits_left - 1, ..chain };
            for b in branches.iter() {
                let weighted = Chain { throughput: chain.throughput * b.scale * b.prob, ..split };
                if let Some(next) = follow(b, weighted).filter(|c| max_component(c.throughput) > 0.0) {
                    radiance += emitted_along(scene, media, next, ctx);
                }
            }
            break;
        }
        let Some(b) = branches.choose(ctx.rng) else { break };
        let Some(next) = follow(&b, Chain { throughput: chain.throughput * b.scale, ..chain }) else { break };
        chain = next;
        if max_component(chain.throughput) <= 0.0 {
            break;
        }
    }
    radiance
}

/// Russian roulette after [`RR_DEPTH`] vertices: whether the path goes on
/// (its weight divided by the chance it did).
#[inline]
pub(super) fn roulette(throughput: &mut Color, vertices: u32, ctx: &mut Context) -> bool {
    if vertices >= RR_DEPTH {
        let q = max_component(*throughput).min(0.95);
        if !(ctx.rng.random::<f32>() < q) {
            return false;
        }
        *throughput /= q;
    }
    max_component(*throughput) > 0.0
}

/// Light scattered at `p` in a medium towards the path (which arrived
/// travelling along `dir`) straight from one light drawn by power, by a
/// shadow ray weighted against the phase function's density.
fn medium_light(
    scene: &Scene,
    media: &Media,
    p: Vec3,
    dir: Vec3,
    phase: Phase,
    medium: Option<u32>,
    ctx: &mut Context,
) -> Color {
    let Some((index, chance)) = scene.pick_light_index(ctx.rng.random::<f32>()) else { return Color::ZERO };
    let light = &scene.lights[index];
    let Some(inc) = sample_li_everywhere(light, p, next_2d(ctx.rng)) else { return Color::ZERO };
    let f = phase.eval(dir, inc.dir);
    if !(f > 0.0) || inc.intensity == Color::ZERO {
        return Color::ZERO;
    }
    let ray = Ray::new(p, inc.dir);
    let reach = inc.target.map_or(f32::INFINITY, |y| (y - p).length());
    let tr = transmittance(scene, media, ray, None, reach, inc.prim, medium, ctx);
    if tr == Color::ZERO {
        return Color::ZERO;
    }
    let w = if light.is_delta() {
        1.0
    } else {
        let at = Scattered { point: p, normal: None, pdf: f };
        power_heuristic(1.0, chance * light_pdf(light, &at, inc.dir, inc.target), 1.0, f)
    };
    inc.intensity * tr * (f * w / chance)
}

/// Light reflected at a surface vertex straight from the lights: the mean
/// of `count` shadow rays, each to a light drawn by power, their samples
/// of the light stratified; each weighted against the BSDF's density
/// (`mis`, which one shadow ray's weight assumes: `count` 1) or counted
/// in full.
#[allow(clippy::too_many_arguments)]
pub(super) fn surface_light(
    scene: &Scene,
    media: &Media,
    hit: &Hit,
    material: &Material,
    frame: &Frame,
    wo: Vec3,
    entering: bool,
    medium: Option<u32>,
    mis: bool,
    count: u32,
    sequence: Option<(u64, u64)>,
    ctx: &mut Context,
) -> Color {
    let count = count.max(1);
    // A camera sample's shadow rays take their block of a sequence of the
    // pixel's, scrambled apart from its gather rays' (as those, they stay
    // stratified over the light across the pixel's samples and passes).
    let sequence =
        sequence.map(|(index, scramble)| GatherSequence::new(index, scramble ^ SHADOW_SEQUENCE, count).rotated(count));
    let mut sum = Color::ZERO;
    for s in 0..count {
        let point = sequence.as_ref().map(|q| q.point(s));
        sum +=
            surface_light_sample(scene, media, hit, material, frame, wo, entering, medium, mis, (s, count), point, ctx);
    }
    sum / count as f32
}

/// Keys the shadow rays' sequence apart from the gather rays'.
const SHADOW_SEQUENCE: u64 = 0x5AD0_5EED_0000_0002;

/// One shadow ray of [`surface_light`]: its sample of the light at
/// `point`, or in stratum `stratum.0` of `stratum.1`.
#[allow(clippy::too_many_arguments)]
fn surface_light_sample(
    scene: &Scene,
    media: &Media,
    hit: &Hit,
    material: &Material,
    frame: &Frame,
    wo: Vec3,
    entering: bool,
    medium: Option<u32>,
    mis: bool,
    stratum: (u32, u32),
    point: Option<glam::Vec2>,
    ctx: &mut Context,
) -> Color {
    let Some((index, chance)) = scene.pick_light_index(ctx.rng.random::<f32>()) else { return Color::ZERO };
    let light = &scene.lights[index];
    let n = frame.n;
    let u = match (point, stratum) {
        (Some(u), _) => u,
        (None, (_, 1)) => next_2d(ctx.rng),
        (None, (s, count)) => crate::sampling::stratified_2d(s, count, next_2d(ctx.rng)),
    };
    let Some(inc) = light.sample_li(hit.point, n, u) else { return Color::ZERO };
    let wi = frame.to_local(inc.dir);
    let cos = wi.z;
    // The side of the actual surface the light arrives on must be the
    // side the shading frame says.
    if hit.shading_normal != hit.normal && !hit.leaves_as(-n, inc.dir, cos > 0.0) {
        return Color::ZERO;
    }
    let f = material.eval(wo, wi, entering, Transport::Radiance);
    if f == Color::ZERO || inc.intensity == Color::ZERO {
        return Color::ZERO;
    }
    let (shadow, dep) = hit.spawn(inc.dir);
    let reach = inc.target.map_or(f32::INFINITY, |y| (y - shadow.origin).length());
    let start = media.after(medium, hit.prim, hit.normal, inc.dir);
    let tr = transmittance(scene, media, shadow, Some(dep), reach, inc.prim, start, ctx);
    if tr == Color::ZERO {
        return Color::ZERO;
    }
    let w = if light.is_delta() || !mis {
        1.0
    } else {
        let pdf = material.pdf(wo, wi, entering);
        let at = Scattered { point: hit.point, normal: Some(n), pdf };
        power_heuristic(1.0, chance * light_pdf(light, &at, inc.dir, inc.target), 1.0, pdf)
    };
    f * inc.intensity * tr * (cos.abs() * w / chance)
}

/// What reaches the end of a shadow ray (at distance `reach`, or light
/// `target`'s own surface) of the light leaving it: the media's
/// transmittance along it and what each index-matched surface it crosses
/// lets through; zero where any other surface blocks it.
#[allow(clippy::too_many_arguments)]
pub(super) fn transmittance(
    scene: &Scene,
    media: &Media,
    mut ray: Ray,
    mut departure: Option<Departure>,
    mut reach: f32,
    target: Option<u32>,
    mut medium: Option<u32>,
    ctx: &mut Context,
) -> Color {
    let mut tr = Color::ONE;
    for _ in 0..MAX_CROSSINGS {
        ctx.counters.rays += 1;
        let hit = scene.intersect_within(&ray, departure, reach).filter(|h| Some(h.prim) != target);
        let segment = hit.as_ref().map_or(reach, |h| h.t);
        if let Some(m) = medium {
            tr *= media.get(m).transmittance(&ray, segment.max(0.0), ctx.rng);
        }
        let Some(h) = hit else { return tr };
        let material = scene.material_seen(&h, ray.dir);
        tr *= passes_straight(&material, h.shading_normal.dot(ray.dir).abs());
        if tr == Color::ZERO {
            return tr;
        }
        medium = media.after(medium, h.prim, h.normal, ray.dir);
        (ray, departure) = {
            let (r, d) = h.spawn(ray.dir);
            (r, Some(d))
        };
        reach -= h.t;
    }
    Color::ZERO
}

/// What a surface lets straight through, unchanged in direction, of light
/// arriving at cosine `cos` with its normal: all of a `null` surface, a
/// mask's open share, a thin pane's transmission (1 - R', R' its
/// reflectance with the inter-reflections, times its transmittance: the
/// null transmission of Mitsuba 3's thindielectric.cpp); none of any other.
pub fn passes_straight(material: &Material, cos: f32) -> Color {
    match material {
        Material::Masked(m) => Color::splat(m.through()),
        Material::ThinDielectric(t) => t.specular_transmittance * (1.0 - t.reflectance(cos)),
        _ => Color::ZERO,
    }
}

/// A sample of `light` for a point in a medium, which light reaches from
/// every side: light from everywhere uniformly over the sphere (its own
/// sampling is by the cosine about a surface's normal), every other
/// light by its own sampling.
#[inline]
pub(super) fn sample_li_everywhere(light: &Light, p: Vec3, u: glam::Vec2) -> Option<Incident> {
    match light {
        Light::Constant(c) => {
            let dir = crate::sampling::uniform_cone(u, -1.0).normalize();
            Some(Incident { dir, target: None, intensity: c.radiance * (4.0 * PI), prim: None })
        }
        // Any normal: the other lights do not sample about it.
        _ => light.sample_li(p, Vec3::Z, u),
    }
}

/// The density with which the lights' sampling at the vertex `at` draws
/// unit direction `dir` of `light` (ending at `target` on it): an area
/// light's by its area, light from everywhere's by its own sampling (about
/// a surface's normal, over the sphere in a medium).
#[inline]
fn light_pdf(light: &Light, at: &Scattered, dir: Vec3, target: Option<Vec3>) -> f32 {
    match (light, at.normal, target) {
        (Light::Area(a), _, Some(y)) => a.pdf_at(at.point, y),
        (Light::Constant(_), None, _) => 1.0 / (4.0 * PI),
        (_, n, _) => light.pdf_li(at.point, n.unwrap_or(Vec3::Z), dir),
    }
}

/// Radiance leaving the area light met at `hit` by the direction drawn at
/// `last`: its MIS weight against the lights' sampling there.
#[inline(never)]
fn emitted_weight(scene: &Scene, last: &Scattered, hit: &Hit) -> f32 {
    let (Some(area), Some(index)) = (scene.light_of(hit.prim), scene.light_index_of(hit.prim)) else {
        // A glowing surface no light samples: its light is found only here.
        return 1.0;
    };
    let pdf = scene.light_prob(index) * area.pdf_at(last.point, hit.point);
    power_heuristic(1.0, last.pdf, 1.0, pdf)
}

/// Light from everywhere arriving along `dir` by the direction drawn at
/// `last`, each light at infinity weighted against its own sampling.
#[inline(never)]
fn from_infinity(scene: &Scene, last: &Scattered, dir: Vec3) -> Color {
    let mut sum = Color::ZERO;
    for &index in scene.lights_at_infinity() {
        let (index, light) = (index as usize, &scene.lights[index as usize]);
        let le = light.radiance_from_infinity(dir);
        if le != Color::ZERO {
            let pdf = scene.light_prob(index) * light_pdf(light, last, dir, None);
            sum += le * power_heuristic(1.0, last.pdf, 1.0, pdf);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::{emitted_along, emitted_part, Chain};
    use crate::integrator::Context;
    use crate::math::max_component;
    use crate::sampling::{stream, Domain};
    use crate::scene::Scene;
    use crate::stats::Counters;
    use glam::Vec2;

    /// A disk light above a glass ball in fog, seen from the side through
    /// the ball (suite scene 13 without its walls): rays towards the ball's
    /// upper half see the light refracted twice, or after an internal
    /// reflection (a share of a few percent).
    const BALL_IN_FOG: &str = r#"
[camera]
eye = [2.0, 0.15, 1.5]
target = [2.0, 2.0, 1.05]
up = [0, 0, 1]
vfov = 58
width = 200
height = 200
medium = "fog"

[materials.glass]
type = "glass"
ior = 1.5

[media.fog]
type = "homogeneous"
sigma_t = [0.25, 0.25, 0.25]
albedo = [0.8, 0.8, 0.8]

[[shapes]]
type = "sphere"
center = [2.0, 2.0, 1.3]
radius = 0.5
material = "glass"
exterior = "fog"

[[lights]]
type = "disk"
center = [2.0, 2.0, 2.999]
normal = [0, 0, -1]
radius = 0.2
radiance = [400, 400, 400]
"#;

    /// The emitted part follows both branches at glass: each ray's estimate
    /// is (in a homogeneous medium, up to what lies beyond the split
    /// vertices) the same whatever the random stream, and its sum over the
    /// rays is the mean of the estimator that chooses one branch by its
    /// share, which left rays that see the light after an internal
    /// reflection reading 0 or the light's full radiance.
    #[test]
    fn the_emitted_part_through_glass_is_every_branch_s_share() {
        let file = crate::scene::file::parse(BALL_IN_FOG, std::path::Path::new("ball.toml")).unwrap();
        let scene = Scene::from_parts(file.parts);
        let media = scene.media().expect("the scene has fog");
        let mut counters = Counters::default();
        let (mut split_sum, mut chosen_sum, mut chosen_var) = (0.0f64, 0.0f64, 0.0f64);
        let (mut seen, mut rare) = (0, 0);
        const CHOSEN: u64 = 2000;
        for i in 0..8 * 16 * 4u64 {
            // Where the 200 x 200 view sees the light in the ball (rows
            // 29-36, columns 92-107), four points a pixel.
            let (pixel, sub) = (i / 4, i % 4);
            let (col, row) = (92 + (pixel % 16) as u32, 29 + (pixel / 16) as u32);
            let u = Vec2::new(0.25 + 0.5 * (sub % 2) as f32, 0.25 + 0.5 * (sub / 2) as f32);
            let ray = scene.camera.sample_ray(col, row, u, Vec2::ZERO);
            let mut estimate = |splits: u32, k: u64| {
                let mut rng = stream(7, Domain::Camera, i * 1_000_003 + k);
                let mut ctx = Context { rng: &mut rng, counters: &mut counters, pixel: 0 };
                let c = match splits {
                    0 => emitted_along(&scene, media, Chain::from_eye(ray, media, 0), &mut ctx),
                    _ => emitted_part(&scene, media, ray, &mut ctx),
                };
                max_component(c) as f64
            };
            let (a, b) = (estimate(4, 0), estimate(4, 1));
            assert!((a - b).abs() <= 1e-3 * a.max(1.0), "ray {i}: {a} and {b} from two streams");
            let samples: Vec<f64> = (0..CHOSEN).map(|k| estimate(0, k + 2)).collect();
            let mean = samples.iter().sum::<f64>() / CHOSEN as f64;
            let var = samples.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (CHOSEN - 1) as f64;
            split_sum += a;
            chosen_sum += mean;
            chosen_var += var / CHOSEN as f64;
            seen += (a > 1.0) as u32;
            // A ray whose one-branch samples spread wider than their mean.
            rare += (mean > 1.0 && var.sqrt() > mean) as u32;
        }
        assert!(seen > 20 && rare > 5, "{seen} rays see the light, {rare} through a rare branch");
        let se = chosen_var.sqrt();
        assert!((split_sum - chosen_sum).abs() < 4.0 * se, "split {split_sum} against chosen {chosen_sum} ± {se}");
    }
}
