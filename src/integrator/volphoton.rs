//! Photon mapping's camera pass in a scene with participating media
//! (Jensen and Christensen 1998; the beam radiance estimate of Jarosz,
//! Zwicker and Jensen 2008 for volume caustics). A camera path follows
//! mirrors, glass, index-matched crossings and glossy lobes; each light
//! path reaching the eye is counted by exactly one estimator
//! (notes/method.md §8):
//!
//! | light path                    | estimator                                   |
//! |-------------------------------|---------------------------------------------|
//! | L E, L S+ E (through media)   | emission met, times transmittance           |
//! | L V (S\|G)* E                 | single scattering: a distance drawn along   |
//! |                               | each camera segment, a shadow ray to a light|
//! | L S+ V (S\|G)* E              | volume caustic map, beam estimate           |
//! | L …(D\|V)… V (S\|G)* E        | global volume photons' grid, integrated     |
//! |                               | along the segment cell by cell              |
//! | L D (S\|G)* E                 | shadow rays at the diffuse or glossy vertex |
//! | L …(S\|D\|V)… D (S\|G)* E     | surface map (global and caustic photons),   |
//! |                               | read directly at the diffuse vertex; with   |
//! |                               | final gathering, through a cache of it, and |
//! |                               | L … D S* D (S\|G)* E by gather rays instead |
//! |                               | ([`super::volgather`])                      |
//! | L S+ G (S\|G)* E              | emission met after the specular chain       |
//!
//! Transmittance along camera segments is exact in both kinds of media
//! (a heterogeneous one's integrated along its grid's cells); shadow rays
//! estimate it by ratio tracking in heterogeneous ones. Surfaces behind a
//! medium are seen through it. The maps are read directly, so their
//! radii shrink from pass to pass as progressive photon mapping's do; with
//! final gathering, the light of diffuse lobes' paths through the
//! irradiance cache at the gather rays' ends.

use super::volpath::{emitted_part, roulette, sample_li_everywhere, surface_light, transmittance};
use super::{Context, Integrator, Part};
use crate::material::Transport;
use crate::math::{max_component, Color, Ray};
use crate::medium::{LitGrid, LitSegment, Media, Medium, Steps};
use crate::photon::irradiance_cache::IrradianceCache;
use crate::photon::map::{PhotonMap, Scratch};
use crate::photon::volume_grid::VolumeGrid;
use crate::photon::volume_map::VolumeMap;
use crate::sampling::{next_2d, stream, Domain};
use crate::scene::Scene;
use crate::shape::Departure;
use rand::RngExt;

/// Hard cap on a camera path's events (vertices and crossings).
const MAX_EVENTS: u32 = 256;

/// The estimator over one pass's maps.
pub struct VolPhotonIntegrator<'a> {
    pub scene: &'a Scene,
    pub media: &'a Media,
    /// Photons on diffuse surfaces, read directly at a diffuse camera
    /// vertex: every path but light straight from a light; with `cache`,
    /// only those whose last vertex but specular ones was not a diffuse
    /// lobe's, read through `surface_cache`.
    pub surface: &'a PhotonMap,
    /// Final gathering: the irradiance of every surface photon, read at
    /// the gather rays' ends ([`super::volgather`]); `None`: none.
    pub cache: Option<&'a IrradianceCache>,
    /// With final gathering, `surface`'s irradiance at every stride-th of
    /// its photons, read at a diffuse camera vertex in place of the k
    /// nearest photons: a search of the k nearest at every camera sample
    /// cost 29% of 14-smoke's camera pass for 1.8% of its light
    /// (notes/method.md §8).
    pub surface_cache: Option<&'a IrradianceCache>,
    /// Gather rays per diffuse camera vertex.
    pub gather_rays: u32,
    /// Photons scattered in media after a diffuse or medium vertex, as a
    /// grid of the light they scatter.
    pub volume: &'a VolumeGrid,
    /// Photons scattered in media straight after mirrors and glass.
    pub volume_caustic: &'a VolumeMap,
    /// The surface map's k nearest photons and radius cap.
    pub k: usize,
    pub r_max: f32,
    /// Single-scattering samples per camera segment in a medium,
    /// stratified along it.
    pub single_samples: u32,
    /// Shadow rays per smooth camera vertex on a surface (`--shadow-rays`),
    /// their samples of the lights stratified.
    pub shadow_rays: u32,
}

/// Cells along the longest side of a medium's grid of where the lights
/// reach (12-fog-shafts: 0.125 m cells, its window 6 x 5 of them).
const LIT_CELLS: u32 = 32;

/// Shadow rays per cell of that grid.
const LIT_POINTS: u32 = 4;

/// A thread's scratch space.
#[derive(Default)]
pub struct VolPhotonThread {
    scratch: Scratch,
    steps: Steps,
    lit: LitSegment,
    gathered: Vec<super::volgather::PendingGather>,
}

/// Where the lights reach into medium `m`: over the scene's bounds, each
/// cell's mean, over `LIT_POINTS` uniform points in it, of the luminance
/// a shadow ray to a light drawn by power brings (transmittance
/// included, no phase function). Its streams are keyed by (medium, cell)
/// alone: the same grid on any thread count and in every pass, a
/// sampling density only (any grid gives the same expectation).
fn lit_grid(scene: &Scene, media: &Media, m: u32, counters: &mut crate::stats::Counters) -> LitGrid {
    let (lo, hi) = scene.bounds();
    let res = LitGrid::resolution(lo, hi, LIT_CELLS);
    let cells = (res[0] * res[1] * res[2]) as usize;
    let light: Vec<f32> = (0..cells)
        .map(|i| {
            let mut rng = stream(0, Domain::MediumPilot, (u64::from(m) << 32) | i as u64);
            let mut ctx = Context { rng: &mut rng, counters: &mut *counters, pixel: 0 };
            let (corner, size) = LitGrid::cell_box(lo, hi, res, i);
            let mut sum = 0.0f32;
            for _ in 0..LIT_POINTS {
                let u = glam::Vec3::new(ctx.rng.random(), ctx.rng.random(), ctx.rng.random());
                let p = corner + size * u;
                let Some((index, chance)) = scene.pick_light_index(ctx.rng.random::<f32>()) else { continue };
                let Some(inc) = sample_li_everywhere(&scene.lights[index], p, next_2d(ctx.rng)) else { continue };
                if inc.intensity == Color::ZERO {
                    continue;
                }
                let reach = inc.target.map_or(f32::INFINITY, |y| (y - p).length());
                let shadow =
                    transmittance(scene, media, Ray::new(p, inc.dir), None, reach, inc.prim, Some(m), &mut ctx);
                sum += crate::texture::luminance(inc.intensity * shadow) / chance;
            }
            sum / LIT_POINTS as f32
        })
        .collect();
    LitGrid::new(lo, hi, res, &light)
}

/// What a pixel's samples share: the camera sample's place in the
/// pixel's sequence over all passes and the pixel's scramble
/// ([`Integrator::start_sample`]), for the first diffuse vertex's gather
/// rays, which then stay stratified over the hemisphere across the pixel's
/// samples and passes, as in a scene without media.
#[derive(Default)]
pub struct VolPhotonPixel {
    sequence: Option<(u64, u64)>,
}

impl Integrator for VolPhotonIntegrator<'_> {
    type Thread = VolPhotonThread;
    type Pixel = VolPhotonPixel;

    fn radiance(
        &self,
        ray: Ray,
        part: Part,
        ctx: &mut Context,
        thread: &mut VolPhotonThread,
        pixel: &mut VolPhotonPixel,
    ) -> Color {
        let sequence = pixel.sequence.take();
        // A whole sample is the two parts apart: the emitted part follows
        // both branches at glass, where the path follows one.
        match part {
            Part::Emitted => emitted_part(self.scene, self.media, ray, ctx),
            Part::Reflected => self.path(ray, part, sequence, ctx, thread),
            Part::All => {
                emitted_part(self.scene, self.media, ray, ctx) + self.path(ray, Part::Reflected, sequence, ctx, thread)
            }
        }
    }

    fn start_sample(&self, pixel: &mut VolPhotonPixel, index: u64, scramble: u64) {
        pixel.sequence = Some((index, scramble));
    }
}

impl VolPhotonIntegrator<'_> {
    /// `sequence`: the camera sample's place in its pixel's sequence and
    /// the pixel's scramble, whose block of points the first diffuse
    /// vertex's gather rays take ([`super::photon::gather::GatherSequence`]).
    fn path(
        &self,
        mut ray: Ray,
        part: Part,
        mut sequence: Option<(u64, u64)>,
        ctx: &mut Context,
        thread: &mut VolPhotonThread,
    ) -> Color {
        let (scene, media) = (self.scene, self.media);
        let hide_emitters = scene.paths.hide_emitters;
        let mut radiance = Color::ZERO;
        let mut throughput = Color::ONE;
        let mut departure: Option<Departure> = None;
        let mut medium = media.camera;
        // Vertices so far (crossings are none); whether all were specular
        // (light met is then the emitted part's: the throughput carries
        // only the transmittance of the media crossed, the light that
        // reached the eye unscattered); whether light met now is this
        // estimator's (no shadow ray could have found it).
        let (mut vertices, mut specular_chain, mut count_emitted) = (0u32, true, true);
        for _ in 0..MAX_EVENTS {
            ctx.counters.rays += 1;
            let hit = scene.intersect(&ray, departure);
            let t_surface = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
            if let Some(m) = medium {
                let med = media.get(m);
                let tr = med.track(&ray, t_surface, &mut thread.steps);
                if med.scatters() {
                    let inscattered = self.segment(med, m, &ray, t_surface, tr, ctx, thread);
                    radiance += throughput * ctx.checked(inscattered, "medium");
                }
                throughput *= tr;
            }
            if !(max_component(throughput) > 0.0) {
                break;
            }
            let seen = (part == Part::All || !specular_chain) && count_emitted && !(vertices == 0 && hide_emitters);
            let Some(hit) = hit else {
                if seen {
                    radiance += throughput * scene.background(ray.dir);
                }
                break;
            };
            throughput *= scene.transmittance(departure, hit.t);
            if seen {
                radiance += throughput * scene.emitted(&hit, ray.dir);
            }
            let material = scene.material_seen(&hit, ray.dir);
            if material.is_emitter() {
                break;
            }
            let (frame, entering) = hit.scattering_frame(ray.dir, &material);
            let wo = frame.to_local(-ray.dir);
            if material.has_smooth_lobes() {
                // The first such vertex's rays take the sample's block of
                // the pixel's sequences.
                let vertex_sequence = sequence.take();
                let direct = surface_light(
                    scene,
                    media,
                    &hit,
                    &material,
                    &frame,
                    wo,
                    entering,
                    medium,
                    false,
                    self.shadow_rays,
                    vertex_sequence,
                    ctx,
                );
                let mut reflected = ctx.checked(direct, "direct");
                if material.diffuse_rho().is_some() {
                    let rho = material.diffuse_albedo(wo);
                    let r = match self.surface_cache {
                        Some(read) => rho / std::f32::consts::PI * self.cached(read, hit.point, frame.n, ctx),
                        None => {
                            self.surface.radiance_cone(hit.point, frame.n, rho, self.k, self.r_max, &mut thread.scratch)
                        }
                    };
                    reflected += ctx.checked(r, "surface map");
                    if let Some(cache) = self.cache {
                        let g = self.gather(cache, &hit, frame.n, medium, vertex_sequence, &mut thread.gathered, ctx);
                        reflected += rho * g;
                    }
                }
                radiance += throughput * reflected;
            }
            // The path goes on by a specular branch or the glossy lobe
            // (each, where there are both, half the time).
            let branches = material.specular_branches(wo, entering, Transport::Radiance);
            let glossy = material.glossy();
            let both = !branches.is_empty() && glossy.is_some();
            let pick_glossy = glossy.is_some() && (!both || ctx.rng.random::<f32>() < 0.5);
            let split = if both { 2.0 } else { 1.0 };
            let (wi, weight, is_glossy) = if pick_glossy {
                let Some(g) = glossy else { break };
                let Some((wi, w)) = g.sample(wo, entering, Transport::Radiance, ctx.rng) else { break };
                (wi, w, true)
            } else {
                let several = branches.iter().count() > 1;
                let Some(b) = branches.choose(ctx.rng) else { break };
                (b.wi, if several { b.scale } else { b.scale * b.prob }, false)
            };
            throughput *= weight * split;
            if !is_glossy && wi == -wo {
                // Straight through an index-matched surface.
                medium = media.after(medium, hit.prim, hit.normal, ray.dir);
                let (next, dep) = hit.spawn(ray.dir);
                (ray, departure) = (next, Some(dep));
                continue;
            }
            let dir = frame.to_world(wi).normalize();
            if hit.shading_normal != hit.normal && !hit.leaves_as(ray.dir, dir, wi.z > 0.0) {
                break;
            }
            vertices += 1;
            count_emitted = !is_glossy;
            specular_chain &= !is_glossy;
            medium = media.after(medium, hit.prim, hit.normal, dir);
            let (next, dep) = hit.spawn(dir);
            (ray, departure) = (next, Some(dep));
            if !roulette(&mut throughput, vertices, ctx) {
                break;
            }
        }
        radiance
    }

    /// Light scattered towards the eye along the camera segment `ray` over
    /// [0, `t_max`] in medium `m` (whose transmittance [`Medium::track`]
    /// left in the thread's steps): single scattering by shadow rays, the
    /// rest by the volume caustic map's beam estimate and the global volume
    /// photons' grid. `across`: the transmittance over the whole segment.
    #[allow(clippy::too_many_arguments)]
    fn segment(
        &self,
        med: &Medium,
        m: u32,
        ray: &Ray,
        t_max: f32,
        across: Color,
        ctx: &mut Context,
        thread: &mut VolPhotonThread,
    ) -> Color {
        let grid = self.media.lit_grid(m, || lit_grid(self.scene, self.media, m, ctx.counters));
        let drawable = thread.lit.build(med, grid, ray, t_max, across, &thread.steps);
        let steps = &thread.steps;
        let mut sum = Color::ZERO;
        self.volume_caustic.beam(ray, t_max, |c| {
            if c.photon.medium == m {
                let f = med.phase.eval(c.photon.direction(), -ray.dir);
                sum += c.photon.power * (f * c.kernel) * med.transmittance_to(steps, c.t);
            }
        });
        let mut cursor = 0;
        sum += self.volume.integrate(m, &med.phase, ray, t_max, |t| med.transmittance_along(steps, &mut cursor, t));
        // The samples stratified along the segment (in the distances'
        // distribution, transmittance times where the lights reach): a
        // shaft of light crossing a small part of it is met by most of
        // them in every camera ray.
        let n = self.single_samples.max(1);
        let mut single = Color::ZERO;
        for i in (0..n).filter(|_| drawable) {
            let u = (i as f32 + ctx.rng.random::<f32>()) / n as f32;
            single += self.single_scattering(med, m, ray, &thread.lit, u, ctx, steps);
        }
        sum + single / n as f32
    }

    /// One estimate of the light scattered once along the segment: a
    /// distance drawn from `lit` (`u`: its place in their distribution), one
    /// light drawn by power, a shadow ray.
    #[allow(clippy::too_many_arguments)]
    fn single_scattering(
        &self,
        med: &Medium,
        m: u32,
        ray: &Ray,
        lit: &LitSegment,
        u: f32,
        ctx: &mut Context,
        steps: &Steps,
    ) -> Color {
        let channel = ctx.rng.random::<f32>();
        let Some((t, pdf_t)) = lit.sample(glam::Vec2::new(channel, u)) else {
            return Color::ZERO;
        };
        let p = ray.at(t);
        let (_, sigma_s) = med.coefficients(p);
        if sigma_s == Color::ZERO {
            return Color::ZERO;
        }
        let scene = self.scene;
        let Some((index, chance)) = scene.pick_light_index(ctx.rng.random::<f32>()) else { return Color::ZERO };
        let Some(inc) = sample_li_everywhere(&scene.lights[index], p, next_2d(ctx.rng)) else { return Color::ZERO };
        let f = med.phase.eval(ray.dir, inc.dir);
        if !(f > 0.0) || inc.intensity == Color::ZERO {
            return Color::ZERO;
        }
        let reach = inc.target.map_or(f32::INFINITY, |y| (y - p).length());
        let shadow = transmittance(scene, self.media, Ray::new(p, inc.dir), None, reach, inc.prim, Some(m), ctx);
        if shadow == Color::ZERO {
            return Color::ZERO;
        }
        med.transmittance_to(steps, t) * sigma_s * inc.intensity * shadow * (f / (chance * pdf_t))
    }
}
