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
//! add nothing: those paths belong to the first two rows.

use super::{direct_light, glass_branches, CausticMemo, Context, Integrator, Part, PendingRead};
use crate::material::{Material, Phong};
use crate::math::{max_component, Color, Frame, Ray};
use crate::photon::irradiance_cache::IrradianceCache;
use crate::photon::map::PhotonMap;
use crate::sampling::{cosine_hemisphere, next_2d, stratified_2d};
use crate::scene::{Hit, Scene};
use crate::shape::Departure;
use rand::RngExt;
use std::f32::consts::PI;

/// Camera paths split into both the reflected and refracted branch at their
/// first glass vertices (no noise from the choice where it matters most);
/// deeper, Fresnel picks one branch.
const SPLIT_DEPTH: u32 = 2;
/// Specular chains are cut after this many bounces (light trapped by total
/// internal reflection; its share is negligible).
const MAX_SPECULAR_DEPTH: u32 = 24;

/// A caustic estimate stands in only for points on a surface facing within
/// this (cosine) of its own: the same plane, or a curved surface's nearby
/// point.
const REUSE_NORMAL_COSINE: f32 = 0.999;

/// A gather ray's diffuse hit: where the cache is read, and with what weight.
#[derive(Clone, Copy, Default)]
struct GatherHit {
    point: glam::Vec3,
    normal: glam::Vec3,
    weight: Color,
}

/// Quality settings of the estimator.
#[derive(Clone, Copy, Debug)]
pub struct PhotonEstimator {
    /// Nearest caustic photons per estimate, and the search radius cap.
    pub k_caustic: usize,
    pub r_caustic: f32,
    /// Final-gather rays per diffuse camera hit.
    pub gather_rays: u32,
    /// Shadow rays per light per diffuse camera hit.
    pub shadow_rays: u32,
    /// Skip lights that face away from the shaded point.
    pub skip: bool,
    /// A pixel's later samples reuse its last caustic estimate within this
    /// fraction of its radius, on the same surface (0: never).
    pub caustic_reuse: f32,
}

pub struct PhotonIntegrator<'a> {
    pub scene: &'a Scene,
    pub caustic: &'a PhotonMap,
    pub cache: &'a IrradianceCache,
    pub settings: PhotonEstimator,
}

impl Integrator for PhotonIntegrator<'_> {
    fn radiance(&self, ray: Ray, part: Part, ctx: &mut Context) -> Color {
        self.trace(ray, None, 0, part, Color::ONE, ctx)
    }

    /// Finds every read's cell first (each cell's slot was fetched when its
    /// gather ray hit, and this starts fetching the points), then reads.
    fn resolve(&self, ctx: &mut Context) -> Color {
        let Some(pending) = ctx.pending.take() else {
            return Color::ZERO;
        };
        for p in pending.iter_mut() {
            p.cell = self.cache.locate(p.point);
        }
        let mut sum = Color::ZERO;
        for p in pending.iter() {
            sum += p.weight * self.cache.lookup_in(p.point, p.normal, p.cell, ctx.scratch);
        }
        pending.clear();
        ctx.pending = Some(pending);
        ctx.checked(sum, "indirect")
    }
}

/// In the functions below, `w` is what radiance leaving the current vertex
/// is multiplied by on its way to the camera: the weight of a read left
/// for later (see [`PendingRead`]).
impl PhotonIntegrator<'_> {
    fn trace(
        &self,
        ray: Ray,
        departure: Option<Departure>,
        depth: u32,
        part: Part,
        w: Color,
        ctx: &mut Context,
    ) -> Color {
        ctx.tally.rays += 1;
        let Some(hit) = self.scene.intersect(&ray, departure) else {
            return Color::ZERO;
        };
        let through = self.scene.transmittance(departure, hit.t);
        let w = w * through;
        let radiance = match *self.scene.material(hit.prim) {
            Material::Emitter if part == Part::Reflected => Color::ZERO,
            Material::Emitter => self.scene.light_of(hit.prim).map_or(Color::ZERO, |l| l.radiance_towards(ray.dir)),
            Material::Lambertian { rho } => self.surface(&hit, &ray, rho, None, depth, part, w, ctx),
            Material::Phong(p) => self.surface(&hit, &ray, p.diffuse_rho(), Some(&p), depth, part, w, ctx),
            Material::Mirror { reflectance } => self.mirror(&hit, &ray, reflectance, depth, part, w, ctx),
            Material::Glass { ior, .. } => {
                if depth >= MAX_SPECULAR_DEPTH {
                    return Color::ZERO;
                }
                let branches = glass_branches(&hit, &ray, ior);
                let reflected = |s: &Self, w: Color, ctx: &mut Context| {
                    let (next, dep) = hit.spawn(branches.reflected);
                    s.trace(next, Some(dep), depth + 1, part, w, ctx)
                };
                match branches.refracted {
                    None => reflected(self, w, ctx),
                    Some((wt, radiance_scale)) => {
                        let refracted = |s: &Self, w: Color, ctx: &mut Context| {
                            let (next, dep) = hit.spawn(wt);
                            radiance_scale * s.trace(next, Some(dep), depth + 1, part, w * radiance_scale, ctx)
                        };
                        let r = branches.fresnel;
                        if depth < SPLIT_DEPTH {
                            r * reflected(self, w * r, ctx) + (1.0 - r) * refracted(self, w * (1.0 - r), ctx)
                        } else if ctx.rng.random::<f32>() < r {
                            reflected(self, w, ctx)
                        } else {
                            refracted(self, w, ctx)
                        }
                    }
                }
            }
        };
        through * radiance
    }

    /// Radiance leaving a perfect mirror of `reflectance` along `-ray.dir`.
    #[allow(clippy::too_many_arguments)]
    fn mirror(
        &self,
        hit: &Hit,
        ray: &Ray,
        reflectance: Color,
        depth: u32,
        part: Part,
        w: Color,
        ctx: &mut Context,
    ) -> Color {
        if depth >= MAX_SPECULAR_DEPTH || max_component(reflectance) <= 0.0 {
            return Color::ZERO;
        }
        let (next, dep) = hit.spawn(hit.mirrored(ray.dir));
        reflectance * self.trace(next, Some(dep), depth + 1, part, w * reflectance, ctx)
    }

    /// A surface with a Lambertian lobe `rho` and, for the Phong material,
    /// a glossy lobe and a mirror lobe.
    #[allow(clippy::too_many_arguments)]
    fn surface(
        &self,
        hit: &Hit,
        ray: &Ray,
        rho: Color,
        phong: Option<&Phong>,
        depth: u32,
        part: Part,
        w: Color,
        ctx: &mut Context,
    ) -> Color {
        let mirrored = match phong {
            Some(p) => self.mirror(hit, ray, p.mirror_rho(), depth, part, w, ctx),
            None => Color::ZERO,
        };
        // A glowing surface's own light (zero for all but area lights).
        let mirrored = match part {
            Part::Reflected => mirrored,
            _ => mirrored + self.scene.emitted(hit.prim, ray.dir),
        };
        let glossy = phong.is_some_and(|p| p.specular > 0.0);
        if part == Part::Emitted || (max_component(rho) <= 0.0 && !glossy) {
            return mirrored;
        }
        let n = hit.facing_normal(ray.dir);
        let to_viewer = -ray.dir;
        let brdf = |w: glam::Vec3| phong.map_or(rho / PI, |p| p.brdf(n, w, to_viewer));
        let direct = direct_light(self.scene, hit, n, brdf, self.settings.shadow_rays, self.settings.skip, ctx);
        let (mut caustic, mut indirect) = (Color::ZERO, Color::ZERO);
        if max_component(rho) > 0.0 {
            caustic = self.caustic(hit, n, rho, ctx);
            indirect = self.indirect(hit, n, rho, w, ctx);
        }
        if let Some(p) = phong.filter(|_| glossy) {
            // One gather ray from the glossy lobe: indirect light it reflects.
            if let Some((dir, weight)) = p.sample_glossy(n, to_viewer, next_2d(ctx.rng)) {
                let (next, dep) = hit.spawn(dir);
                indirect += weight * self.gather(next, dep, w * weight, ctx);
            }
        }
        mirrored
            + self.checked(direct, "direct", ctx)
            + self.checked(caustic, "caustic", ctx)
            + self.checked(indirect, "indirect", ctx)
    }

    /// Light → specular+ → x: the caustic map.
    fn caustic(&self, hit: &Hit, n: glam::Vec3, rho: Color, ctx: &mut Context) -> Color {
        if self.caustic.is_empty() {
            return Color::ZERO;
        }
        if let Some(m) = ctx.memo.caustic {
            if m.normal.dot(n) >= REUSE_NORMAL_COSINE && m.point.distance_squared(hit.point) <= m.reach2 {
                ctx.tally.caustic_reused += 1;
                return m.estimate.radiance(rho);
            }
        }
        let s = &self.settings;
        let estimate = self.caustic.cone_estimate(hit.point, n, s.k_caustic, s.r_caustic, ctx.scratch);
        ctx.tally.caustic_estimates += 1;
        if s.caustic_reuse > 0.0 {
            let reach2 = s.caustic_reuse * s.caustic_reuse * estimate.r2;
            ctx.memo.caustic = Some(CausticMemo { point: hit.point, normal: n, reach2, estimate });
        }
        estimate.radiance(rho)
    }

    /// Light → … diffuse y → (specular*) → x: final gathering.
    ///
    /// Each read of the cache is a cache miss (gather hits land anywhere in
    /// the scene): where the camera pass lets it, the reads are left in
    /// `ctx.pending` and made at the end of the pixel's samples, all of
    /// their fetches under way at once (~5% off the camera pass, stop 16);
    /// else made here. The random numbers are drawn in the same order
    /// either way.
    fn indirect(&self, hit: &Hit, n: glam::Vec3, rho: Color, w: Color, ctx: &mut Context) -> Color {
        let count = self.settings.gather_rays;
        if count == 0 || self.cache.is_empty() {
            return Color::ZERO;
        }
        let frame = Frame::from_normal(n);
        // Cosine-weighted directions: f cos / pdf = (rho / pi) cos / (cos / pi) = rho.
        let w = w * rho / count as f32;
        let mut sum = Color::ZERO;
        for g in 0..count {
            let dir = frame.to_world(cosine_hemisphere(stratified_2d(g, count, next_2d(ctx.rng)))).normalize();
            let (ray, dep) = hit.spawn(dir);
            let h = self.gather_hit(ray, dep, ctx);
            sum += self.read(&h, w, ctx);
        }
        rho * sum / count as f32
    }

    /// Radiance arriving along a gather ray that was reflected by a diffuse
    /// surface at least once before: followed through mirrors and glass to
    /// the first diffuse y, where the global map's irradiance is read.
    fn gather(&self, ray: Ray, dep: Departure, w: Color, ctx: &mut Context) -> Color {
        if self.cache.is_empty() {
            return Color::ZERO;
        }
        let h = self.gather_hit(ray, dep, ctx);
        self.read(&h, w, ctx)
    }

    /// The irradiance read at gather hit `h` times its weight; or, where
    /// `ctx.pending` takes reads, zero, the read left there with weight `w`
    /// times the hit's (`w`: what the radiance leaving along the gather ray
    /// is multiplied by on its way to the camera) and its cell's slot
    /// being fetched.
    fn read(&self, h: &GatherHit, w: Color, ctx: &mut Context) -> Color {
        if h.weight == Color::ZERO {
            return Color::ZERO;
        }
        match ctx.pending.as_deref_mut() {
            Some(pending) => {
                self.cache.prefetch_cell(h.point);
                pending.push(PendingRead {
                    point: h.point,
                    normal: h.normal,
                    weight: w * h.weight,
                    ..Default::default()
                });
                Color::ZERO
            }
            None => h.weight * self.cache.lookup(h.point, h.normal, ctx.scratch),
        }
    }

    /// Where a gather ray, followed through mirrors and glass, meets its
    /// first diffuse surface y, and the weight (path throughput times
    /// rho_y / pi) that y's irradiance takes; a zero weight where it meets
    /// none.
    fn gather_hit(&self, mut ray: Ray, mut dep: Departure, ctx: &mut Context) -> GatherHit {
        let mut weight = Color::ONE;
        for _ in 0..MAX_SPECULAR_DEPTH {
            ctx.tally.rays += 1;
            let Some(y) = self.scene.intersect(&ray, Some(dep)) else {
                break;
            };
            weight *= self.scene.transmittance(Some(dep), y.t);
            let material = *self.scene.material(y.prim);
            if let Some(rho_y) = material.diffuse_rho() {
                // A Phong surface's mirror lobe is not followed here: its
                // share of indirect light is left out (notes/scene-format.md).
                return GatherHit { point: y.point, normal: y.facing_normal(ray.dir), weight: weight * rho_y / PI };
            }
            let next_dir = match material {
                Material::Mirror { reflectance } => {
                    weight *= reflectance;
                    y.mirrored(ray.dir)
                }
                Material::Phong(p) if p.mirror > 0.0 => {
                    weight *= p.mirror_rho();
                    y.mirrored(ray.dir)
                }
                Material::Glass { ior, .. } => {
                    let b = glass_branches(&y, &ray, ior);
                    match b.refracted {
                        Some((wt, scale)) if ctx.rng.random::<f32>() >= b.fresnel => {
                            weight *= scale;
                            wt
                        }
                        _ => b.reflected,
                    }
                }
                _ => break,
            };
            (ray, dep) = y.spawn(next_dir.normalize());
        }
        GatherHit::default()
    }

    fn checked(&self, c: Color, estimator: &'static str, ctx: &mut Context) -> Color {
        ctx.checked(c, estimator)
    }
}
