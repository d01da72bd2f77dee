//! The photon-mapping camera pass (Jensen 1996, 2001).
//!
//! A camera ray follows mirrors and glass until it meets a diffuse surface at
//! x (or a light, whose radiance it takes). There the radiance towards the
//! camera is split by the light path that brought it, each path counted by
//! exactly one estimator (notes/method.md):
//!
//! | light path into x        | estimator                                      |
//! |--------------------------|------------------------------------------------|
//! | light → x                | direct: shadow rays to the lights              |
//! | light → specular+ → x    | caustic map, cone-filtered k-nearest estimate  |
//! | light → … diffuse → x    | final gathering: cosine rays from x, through   |
//! |                          | any specular chain, to a diffuse y, reading    |
//! |                          | the global map's irradiance precomputed near y |
//!
//! Gather rays that reach a light (directly or through mirrors and glass)
//! add nothing: those paths belong to the first two rows. At a glossy lobe
//! the direct light's shadow rays share it with the lobe's own sample by
//! multiple importance sampling ([`super::mis`]): a light that sample meets
//! straight away counts with its weight.

use super::aim::{Aim, AimTargets};
use super::mis::BsdfSample;
use super::{direct_light, direct_light_mis, direct_light_shared, Context, Integrator, MisBsdf, Part};
use crate::material::{Branch, Branches, Glossy, Lobe, Material, Transport};
use crate::math::{Color, Frame, Ray};
use crate::photon::aims::Target;
use crate::photon::irradiance_cache::{CellRange, IrradianceCache};
use crate::photon::map::{ConeEstimate, PhotonMap, Scratch};
use crate::photon::spots::Spot;
use crate::sampling::{cosine_hemisphere, next_2d, stratified_2d};
use crate::scene::{Hit, Scene};
use crate::shape::Departure;
use rand::RngExt;
use std::f32::consts::PI;

pub mod gather;
use gather::{gather_density, GatherSequence};

/// Keys the glossy lobe's sequence apart from the diffuse gather rays'
/// (a plastic's base and coat at the same vertex).
const GLOSSY_SEQUENCE: u64 = 0x6105_5EED_0000_0002;
/// Keys the sequence of the glossy sample at the next vertex of each of
/// those rays' paths.
const GLOSSY_SEQUENCE_NEXT: u64 = 0x6105_5EED_0000_0003;

/// Keys the shadow rays' sequence at a camera vertex apart from the
/// others.
const SHADOW_SEQUENCE: u64 = 0x6105_5EED_0000_0004;

/// Camera paths split into both the reflected and refracted branch at their
/// first glass vertices (no noise from the choice where it matters most);
/// deeper, Fresnel picks one branch.
const SPLIT_DEPTH: u32 = 2;
/// The same at rough glass: a camera path follows both branches about
/// each sampled microfacet normal at its first two rough-glass vertices
/// (a frosted ball's near and far side), one chosen by Fresnel deeper.
/// The choice at the far side was most of a frosted ball's noise
/// (notes/suite.md, 09-frosted-glass); a split costs one path more, and
/// two splits at most quadruple the paths of a glossy camera vertex.
pub const ROUGH_SPLITS: u32 = 2;
/// Where a gather path splits at rough glass and the reflected branch
/// carries most of the light (Fresnel's reflectance about the surface's
/// normal at least a half: inside the glass, near or beyond the critical
/// angle), that branch is followed by this many paths, each about a
/// microfacet normal of its own and weighed by their number; the refracted
/// branch by one. A reflected direction turns by twice the microfacet
/// normal's tilt, a refracted one by about a third of it (|1 - 1/eta| at
/// eta 1.5): inside a frosted object the internal reflection is the
/// branch whose light varies most from sample to sample (notes/method.md,
/// "Two paths along the reflected branch").
pub const REFLECTED_PATHS: u32 = 2;
/// Specular chains are cut after this many bounces (light trapped by total
/// internal reflection; its share is negligible).
const MAX_SPECULAR_DEPTH: u32 = 24;

/// A caustic estimate stands in only for points on a surface facing within
/// this (cosine) of its own: the same plane, or a curved surface's nearby
/// point.
const REUSE_NORMAL_COSINE: f32 = 0.999;

/// Quality settings of the estimator.
#[derive(Clone, Copy, Debug)]
pub struct PhotonEstimator {
    /// Nearest caustic photons per estimate, and the search radius cap.
    pub k_caustic: usize,
    pub r_caustic: f32,
    /// Final-gather rays per diffuse camera hit.
    pub gather_rays: u32,
    /// Of the gather rays, how many are aimed at the mirror and glass
    /// objects and bright spots a diffuse camera hit sees (none where it
    /// sees none); fewer than `gather_rays`.
    pub aimed_gather_rays: u32,
    /// Shadow rays per light per diffuse camera hit.
    pub shadow_rays: u32,
    /// Skip lights that face away from the shaded point.
    pub skip: bool,
    /// A pixel's later samples reuse its last caustic estimate within this
    /// fraction of its radius, on the same surface (0: never).
    pub caustic_reuse: f32,
    /// Leave the irradiance cache's reads for the end of the pixel's
    /// samples ([`PendingRead`]); off: each read is made at once (the plain
    /// version, which it must equal to rounding).
    pub defer_reads: bool,
    /// Multiple importance sampling of direct light at glossy lobes with
    /// the lobe's own samples ([`super::mis`]; off: shadow rays alone, the
    /// estimate it must agree with in the mean).
    pub mis: bool,
    /// At how many of a camera path's first rough-glass vertices (from
    /// its first glossy one on) the path follows both the reflected and
    /// the refracted branch about the sampled microfacet normal, each
    /// weighed by its Fresnel share, instead of one chosen by it
    /// ([`ROUGH_SPLITS`]; 0: never, the estimate it must agree with in
    /// the mean).
    pub rough_splits: u32,
    /// How many paths follow the reflected branch where a gather path
    /// splits at rough glass and it carries most of the light
    /// ([`REFLECTED_PATHS`]; 1: one, the estimate it must agree with in
    /// the mean).
    pub reflected_paths: u32,
    /// Whether a camera path's first glossy vertex draws its gather rays'
    /// microfacet normals (the lobe's 2D samples), and each of their paths
    /// its next glossy sample, from the pixel's scrambled Sobol sequences
    /// ([`gather::GatherSequence`]) instead of independent random numbers
    /// (off: the estimate it must agree with in the mean).
    pub stratify_glossy: bool,
    /// Samples of a pixel whose shadow rays take their points from its
    /// sequence: the first pass's. A later pass's draw independent
    /// points, so that passes stay independent estimates, as the
    /// progressive error estimate assumes (continued over passes, the
    /// sequence made a floor's stated error 6.6 times its true error:
    /// tests/error_estimate.rs).
    pub shadow_sequence_samples: u64,
}

/// A read of precomputed irradiance that a camera sample leaves for later:
/// the camera pass resolves a pixel's reads together, so that their cache
/// misses overlap instead of following one another (final gathering's
/// reads land anywhere in the scene; ~5% off the camera pass,
/// notes/performance.md).
#[derive(Clone, Copy, Debug, Default)]
pub struct PendingRead {
    pub point: glam::Vec3,
    pub normal: glam::Vec3,
    /// What the irradiance there is multiplied by on its way to the camera.
    pub weight: Color,
    pub cell: CellRange,
}

/// What a thread keeps between camera rays: scratch space for the map's
/// searches and the reads left for later.
#[derive(Default)]
pub struct PhotonThread<'a> {
    scratch: Scratch,
    pending: Vec<PendingRead>,
    aims: AimTargets<'a>,
}

/// What a pixel's samples share: its last caustic estimate, where it was
/// made, on what surface, and how far from there it may stand in for a new
/// one.
#[derive(Default)]
pub struct PhotonPixel {
    caustic: Option<CausticMemo>,
    /// Where the pixel's aimed gather rays are in their choice of cone: a
    /// golden-ratio sequence from a random start, so that a pixel's few
    /// aimed rays spread over the targets its points see instead of
    /// repeating one (each choice on its own is still uniform).
    aim_pick: Option<f32>,
    /// The camera sample's place in the pixel's sequence over all passes
    /// and the pixel's scramble ([`Integrator::start_sample`]), where the
    /// camera pass gives them: the cosine gather rays of the sample's
    /// diffuse point are then points of a scrambled Sobol sequence that
    /// continues from sample to sample and pass to pass
    /// ([`gather::GatherSequence`]).
    sequence: Option<(u64, u64)>,
}

#[derive(Clone, Copy, Debug)]
struct CausticMemo {
    point: glam::Vec3,
    normal: glam::Vec3,
    reach2: f32,
    estimate: ConeEstimate,
}

/// A camera sample as the estimator sees it: the common context and this
/// integrator's own thread and pixel state.
struct Shade<'s, 'r, 'a> {
    ctx: &'s mut Context<'r>,
    thread: &'s mut PhotonThread<'a>,
    pixel: &'s mut PhotonPixel,
}

pub struct PhotonIntegrator<'a> {
    pub scene: &'a Scene,
    pub caustic: &'a PhotonMap,
    pub cache: &'a IrradianceCache,
    /// Bright spots final gathering aims at.
    pub spots: &'a [Spot],
    /// The mirror and glass objects' bounding spheres, which it aims at too.
    pub targets: &'a [Target],
    pub settings: PhotonEstimator,
}

impl<'a> Integrator for PhotonIntegrator<'a> {
    type Thread = PhotonThread<'a>;
    type Pixel = PhotonPixel;

    fn radiance(
        &self,
        ray: Ray,
        part: Part,
        ctx: &mut Context,
        thread: &mut PhotonThread<'a>,
        pixel: &mut PhotonPixel,
    ) -> Color {
        self.trace(ray, None, 0, part, Color::ONE, &mut Shade { ctx, thread, pixel })
    }

    /// Finds every read's cell first (each cell's slot was fetched when its
    /// gather ray hit, and this starts fetching the points), then reads.
    fn start_sample(&self, pixel: &mut PhotonPixel, index: u64, scramble: u64) {
        pixel.sequence = Some((index, scramble));
    }

    fn finish(&self, ctx: &mut Context, thread: &mut PhotonThread<'a>, _: &mut PhotonPixel) -> Color {
        let pending = &mut thread.pending;
        for p in pending.iter_mut() {
            p.cell = self.cache.locate(p.point);
        }
        let mut sum = Color::ZERO;
        for p in pending.iter() {
            sum += p.weight * self.lookup(p.point, p.normal, p.cell, ctx);
        }
        pending.clear();
        ctx.checked(sum, "indirect")
    }
}

/// In the functions below, `w` is what radiance leaving the current vertex
/// is multiplied by on its way to the camera: the weight of a read left
/// for later (see [`PendingRead`]).
impl<'a> PhotonIntegrator<'a> {
    fn trace(
        &self,
        ray: Ray,
        departure: Option<Departure>,
        depth: u32,
        part: Part,
        w: Color,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        sh.ctx.counters.rays += 1;
        // What the eye meets is the path's vertex depth + 1; a scene may
        // limit how many there are (`PathLimits`).
        let limits = self.scene.paths;
        let within = |vertices: u32| limits.max_depth.is_none_or(|m| vertices <= m);
        // Whether light leaving what the ray meets (a light's own surface, a
        // glowing one, or light from everywhere) is counted.
        let seen = part != Part::Reflected && within(depth + 1) && !(depth == 0 && limits.hide_emitters);
        let Some(hit) = self.scene.intersect(&ray, departure) else {
            return if seen { self.scene.background(ray.dir) } else { Color::ZERO };
        };
        let through = self.scene.transmittance(departure, hit.t);
        let w = w * through;
        let material = &self.scene.material_seen(&hit, ray.dir);
        let emitted = if seen { self.scene.emitted(&hit, ray.dir) } else { Color::ZERO };
        if material.is_emitter() {
            return through * emitted;
        }
        let (frame, entering) = hit.scattering_frame(ray.dir, material);
        let wo = frame.to_local(-ray.dir);
        let branches = material.specular_branches(wo, entering, Transport::Radiance);
        let mut radiance = emitted;
        if !branches.is_empty() && within(depth + 2) {
            radiance = self.specular(&hit, &frame, &branches, depth, part, w, sh) + radiance;
        }
        if part != Part::Emitted && material.has_smooth_lobes() && within(depth + 2) {
            radiance += self.surface(&hit, material, &frame, wo, entering, w, sh);
        }
        through * radiance
    }

    /// Radiance arriving along the specular branches, each scaled: all of
    /// them along the first `SPLIT_DEPTH` vertices of a camera path (no
    /// noise from the choice where it matters most), one chosen by its
    /// share deeper.
    #[allow(clippy::too_many_arguments)]
    fn specular(
        &self,
        hit: &Hit,
        frame: &Frame,
        branches: &Branches,
        depth: u32,
        part: Part,
        w: Color,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        if depth >= MAX_SPECULAR_DEPTH {
            return Color::ZERO;
        }
        let follow = |s: &Self, b: &Branch, w: Color, sh: &mut Shade<'_, '_, 'a>| {
            let (next, dep) = hit.spawn(frame.to_world(b.wi).normalize());
            b.scale * s.trace(next, Some(dep), depth + 1, part, w * b.scale, sh)
        };
        if depth < SPLIT_DEPTH {
            branches.iter().map(|b| b.prob * follow(self, b, w * b.prob, sh)).fold(Color::ZERO, |a, b| a + b)
        } else {
            branches.choose(sh.ctx.rng).map_or(Color::ZERO, |b| follow(self, &b, w, sh))
        }
    }

    /// Light reflected by a surface's smooth lobes: its diffuse lobe by
    /// direct light, the caustic map and final gathering; its glossy lobe
    /// by direct light and gather rays sampled from it (through the
    /// surface, for rough glass): as many as final gathering sends, one
    /// where paths are depth-limited.
    #[allow(clippy::too_many_arguments)]
    fn surface(
        &self,
        hit: &Hit,
        material: &Material,
        frame: &Frame,
        wo: glam::Vec3,
        entering: bool,
        w: Color,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        let n = frame.n;
        let s = &self.settings;
        let both = material.transmits();
        // The glossy lobe's share of direct light is also found by its
        // gather rays (MIS); the diffuse lobe's by shadow rays alone.
        let mis = material.glossy().filter(|_| s.mis);
        // As many gather rays from the glossy lobe as final gathering sends
        // from a diffuse point (one where paths end after it): light that
        // only paths through glossy lobes find (a light seen through
        // frosted glass, or in a rough metal through glass) is no less
        // noisy than a diffuse point's indirect light.
        let glossy_rays = if self.scene.paths.max_depth.is_some() { 1 } else { s.gather_rays.max(1) };
        let rays = glossy_rays as f32;
        // A diffuse point's direct light is shared with its gather rays by
        // MIS where a light at infinity leaves its dim parts to them (an
        // environment map brighter than its mean somewhere) and they are
        // traced: shadow rays drawn by the map's brightness alone are
        // wasted on a sun the point does not see (notes/method.md).
        let shares_with_gathering = mis.is_none()
            && s.mis
            && self.scene.lights_at_infinity().iter().any(|&i| self.scene.lights[i as usize].compensates())
            && self.scene.paths.max_depth.is_none()
            && material.diffuse_rho().is_some()
            && s.gather_rays > 0
            && !self.cache.is_empty();
        // The shadow rays take their points from a sequence of the pixel's,
        // keyed apart from its gather rays' and glossy samples' (see
        // `direct_light`): a penumbra's light stays stratified over the
        // first pass's samples.
        let points =
            sh.pixel.sequence.filter(|&(index, _)| index < s.shadow_sequence_samples).map(|(index, scramble)| {
                GatherSequence::new(index, scramble ^ SHADOW_SEQUENCE, s.shadow_rays).rotated(s.shadow_rays)
            });
        let points = points.as_ref();
        let direct = match mis {
            Some(g) => {
                let bsdf = |w: glam::Vec3| {
                    let wi = frame.to_local(w);
                    let shared = g.eval(wo, wi, entering, Transport::Radiance);
                    let alone = (material.eval(wo, wi, entering, Transport::Radiance) - shared).max(Color::ZERO);
                    MisBsdf { alone, shared, pdf: rays * g.pdf(wo, wi, entering) }
                };
                direct_light_mis(self.scene, hit, n, bsdf, s.shadow_rays, s.skip, both, points, sh.ctx)
            }
            None if shares_with_gathering => {
                // Light from everywhere is shared with the gather rays (all
                // of them together one strategy; their weights in
                // `indirect`): the shadow rays go to the map's parts
                // brighter than its mean, the gather rays find the rest.
                let (nc, na) = self.gather_split(hit, n, sh);
                let aims = &sh.thread.aims;
                let bsdf = |w: glam::Vec3| MisBsdf {
                    alone: Color::ZERO,
                    shared: material.eval(wo, frame.to_local(w), entering, Transport::Radiance),
                    pdf: gather_density(w.dot(n), nc, na, || aims.pdf(w)),
                };
                direct_light_shared(self.scene, hit, n, bsdf, s.shadow_rays, s.skip, both, points, sh.ctx)
            }
            None => {
                let brdf = |w: glam::Vec3| material.eval(wo, frame.to_local(w), entering, Transport::Radiance);
                direct_light(self.scene, hit, n, brdf, s.shadow_rays, s.skip, both, points, sh.ctx)
            }
        };
        let (mut caustic, mut indirect) = (Color::ZERO, Color::ZERO);
        // Longer paths are the maps' and gathering's; a scene that limits
        // paths to two vertices has only direct light here (a limit of
        // three or more is not offered for photon mapping), and the glossy
        // lobe's sample adds only the light it meets.
        if self.scene.paths.max_depth.is_some() {
            let met = match mis {
                Some(g) => self.glossy_light(hit, frame, g, wo, entering, sh),
                None => Color::ZERO,
            };
            return self.checked(direct + met, "direct", sh);
        }
        if material.diffuse_rho().is_some() {
            let rho = material.diffuse_albedo(wo);
            caustic = self.caustic(hit, n, rho, sh);
            indirect = self.indirect(hit, n, rho, w, shares_with_gathering, sh);
        }
        if let Some(g) = material.glossy() {
            // Gather rays from the glossy lobe: indirect light it reflects,
            // and with MIS the direct light they meet (each weighed as one
            // of `rays` samples).
            // Rough glass splits here (each branch's MIS weight still by
            // the lobe's pdf: the shadow rays' weights use the same, so
            // the two sum to one).
            let split = s.rough_splits > 0 && g.splits();
            let splits = s.rough_splits - split as u32;
            // The lobe's rays take their 2D samples from a scrambled Sobol
            // sequence of the pixel, as a diffuse point's cosine rays do
            // (keyed apart from theirs): stratified over the lobe within
            // the camera sample and across the pixel's samples and passes;
            // and so does the next glossy sample on each ray's path (a
            // frosted ball's far side), from a second sequence. Light seen
            // through two rough surfaces is found where the first one's
            // normal lines the second's lobe up with the light: random
            // normals left it in rare bright samples.
            let sequence = sh.pixel.sequence.filter(|_| s.stratify_glossy).map(|(index, scramble)| {
                let at = |key| GatherSequence::new(index, scramble ^ key, glossy_rays);
                let first = at(GLOSSY_SEQUENCE).rotated(glossy_rays);
                (first, at(GLOSSY_SEQUENCE_NEXT).rotated(glossy_rays))
            });
            for r in 0..glossy_rays {
                let branches = match &sequence {
                    Some((q, _)) => g.sample_split_at(wo, entering, Transport::Radiance, split, q.point(r), sh.ctx.rng),
                    None => g.sample_split(wo, entering, Transport::Radiance, split, sh.ctx.rng),
                };
                let next_at = sequence.as_ref().map(|(_, q)| q.point(r));
                for (wi, weight) in branches.into_iter().flatten() {
                    let dir = frame.to_world(wi).normalize();
                    if hit.leaves_as(-frame.n, dir, wi.z > 0.0) {
                        let (next, dep) = hit.spawn(dir);
                        let sample = mis.map(|g| self.bsdf_sample(hit, n, rays * g.pdf(wo, wi, entering)));
                        let weight = weight / rays;
                        indirect +=
                            weight * self.gather(next, dep, Lobe::Glossy, sample, splits, next_at, w * weight, sh);
                    }
                }
            }
        }
        self.checked(direct, "direct", sh)
            + self.checked(caustic, "caustic", sh)
            + self.checked(indirect, "indirect", sh)
    }

    /// What light a glossy lobe's gather ray meets needs for its MIS
    /// weight.
    fn bsdf_sample(&self, hit: &Hit, n: glam::Vec3, pdf: f32) -> BsdfSample {
        BsdfSample { point: hit.point, normal: n, pdf, shadow_rays: self.settings.shadow_rays, compensated: false }
    }

    /// The light a sample of the glossy lobe meets straight from `hit`,
    /// with its MIS weight (the share of direct light its shadow rays left
    /// to it): a scene whose paths end there.
    #[allow(clippy::too_many_arguments)]
    fn glossy_light(
        &self,
        hit: &Hit,
        frame: &Frame,
        g: Glossy<'_>,
        wo: glam::Vec3,
        entering: bool,
        sh: &mut Shade<'_, '_, 'a>,
    ) -> Color {
        let Some((wi, weight)) = g.sample(wo, entering, Transport::Radiance, sh.ctx.rng) else {
            return Color::ZERO;
        };
        let dir = frame.to_world(wi).normalize();
        if !hit.leaves_as(-frame.n, dir, wi.z > 0.0) {
            return Color::ZERO;
        }
        let sample = self.bsdf_sample(hit, frame.n, g.pdf(wo, wi, entering));
        let (ray, dep) = hit.spawn(dir);
        sh.ctx.counters.rays += 1;
        let met = match self.scene.intersect(&ray, Some(dep)) {
            Some(y) => self.scene.transmittance(Some(dep), y.t) * sample.emitted(self.scene, &y, dir),
            None => sample.from_infinity(self.scene, dir),
        };
        weight * met
    }

    /// Light → specular+ → x: the caustic map.
    fn caustic(&self, hit: &Hit, n: glam::Vec3, rho: Color, sh: &mut Shade<'_, '_, 'a>) -> Color {
        if self.caustic.is_empty() {
            return Color::ZERO;
        }
        if let Some(m) = sh.pixel.caustic {
            if m.normal.dot(n) >= REUSE_NORMAL_COSINE && m.point.distance_squared(hit.point) <= m.reach2 {
                sh.ctx.counters.caustic_reused += 1;
                return m.estimate.radiance(rho);
            }
        }
        let s = &self.settings;
        let estimate = self.caustic.cone_estimate(hit.point, n, s.k_caustic, s.r_caustic, &mut sh.thread.scratch);
        sh.ctx.counters.caustic_estimates += 1;
        if s.caustic_reuse > 0.0 {
            let reach2 = s.caustic_reuse * s.caustic_reuse * estimate.r2;
            sh.pixel.caustic = Some(CausticMemo { point: hit.point, normal: n, reach2, estimate });
        }
        estimate.radiance(rho)
    }

    fn checked(&self, c: Color, estimator: &'static str, sh: &mut Shade<'_, '_, 'a>) -> Color {
        sh.ctx.checked(c, estimator)
    }
}
