//! Path tracing with next-event estimation (the course's grade-3/4 renderer),
//! unbiased: the project's own reference.
//!
//! At each diffuse vertex, direct light is estimated by a shadow ray to the
//! lights; a path that then reaches a light after a diffuse bounce adds
//! nothing (that light was already counted). At a vertex with a glossy
//! lobe, the shadow rays and the continuation's direction share the light
//! by multiple importance sampling ([`super::mis`]): the light the
//! continuation meets next is added with its weight. Emission is counted in
//! full on camera rays and after mirror or glass bounces, whose delta lobes
//! a shadow ray cannot sample. Mirror and glass are sampled (Fresnel
//! chooses the branch); Russian roulette on the path's throughput ends long
//! paths without bias.

use super::mis::BsdfSample;
use super::{direct_light, direct_light_mis, Context, Integrator, MisBsdf, Part};
use crate::material::{Lobe, Scatter, Transport};
use crate::math::{max_component, Color, Ray};
use crate::scene::Scene;
use rand::RngExt;

/// Russian roulette starts after this many bounces.
const RR_DEPTH: u32 = 3;
/// Hard cap on path length (light trapped by total internal reflection).
const MAX_DEPTH: u32 = 256;

pub struct PathIntegrator<'a> {
    pub scene: &'a Scene,
    /// Shadow rays per light at each diffuse vertex.
    pub shadow_rays: u32,
    /// Skip lights that face away from the shaded point.
    pub skip: bool,
    /// Multiple importance sampling of direct light at vertices with a
    /// glossy lobe (off: shadow rays alone, the estimate it must agree
    /// with in the mean).
    pub mis: bool,
}

impl Integrator for PathIntegrator<'_> {
    type Thread = ();
    type Pixel = ();

    fn radiance(&self, ray: Ray, part: Part, ctx: &mut Context, _: &mut (), _: &mut ()) -> Color {
        if let Some(media) = self.scene.media() {
            return super::volpath::radiance(self, media, ray, part, ctx);
        }
        let mut radiance = Color::ZERO;
        let mut throughput = Color::ONE;
        let (mut ray, mut departure) = (ray, None);
        // Whether a light met now is counted: on camera rays and after specular bounces.
        let mut count_emission = true;
        // Whether every vertex so far was specular (the path is E S* so far).
        let mut specular_chain = true;
        // Where the last vertex shared its direct light with the direction
        // drawn from it: the light met now is added with its MIS weight.
        let mut shared: Option<BsdfSample> = None;
        // This hit is the path's vertex depth + 1 after the eye; a scene
        // may limit how many there are (Mitsuba's max_depth).
        let limits = self.scene.paths;
        let within = |vertices: u32| limits.max_depth.is_none_or(|m| vertices <= m);
        for depth in 0..MAX_DEPTH {
            if !within(depth + 1) {
                break;
            }
            ctx.counters.rays += 1;
            let wanted = match part {
                Part::All => true,
                Part::Emitted => specular_chain,
                Part::Reflected => !specular_chain,
            };
            let hidden = depth == 0 && limits.hide_emitters;
            let Some(hit) = self.scene.intersect(&ray, departure) else {
                // Light from everywhere, where shadow rays did not count it.
                if count_emission && wanted && !hidden {
                    radiance += throughput * self.scene.background(ray.dir);
                } else if let Some(b) = shared.filter(|_| wanted) {
                    radiance += throughput * b.from_infinity(self.scene, ray.dir);
                }
                break;
            };
            throughput *= self.scene.transmittance(departure, hit.t);
            let material = &self.scene.material_seen(&hit, ray.dir);
            if count_emission && wanted && !hidden {
                // A light's own surface, or a glowing one; after a diffuse
                // bounce the shadow rays counted it.
                radiance += throughput * self.scene.emitted(&hit, ray.dir);
            } else if let Some(b) = shared.filter(|_| wanted) {
                radiance += throughput * b.emitted(self.scene, &hit, ray.dir);
            }
            if material.is_emitter() {
                break;
            }
            let (frame, entering) = hit.scattering_frame(ray.dir, material);
            let n = frame.n;
            let wo = frame.to_local(-ray.dir);
            let scatter = if part == Part::Emitted {
                // Only a specular lobe continues a specular chain.
                let Some(b) = material.specular_branches(wo, entering, Transport::Radiance).choose(ctx.rng) else {
                    break;
                };
                Scatter { wi: b.wi, weight: b.scale, lobe: Lobe::Specular }
            } else {
                let lit = material.has_smooth_lobes() && within(depth + 2);
                let mis = lit && self.mis && material.glossy().is_some();
                if lit {
                    let (count, skip, both) = (self.shadow_rays, self.skip, material.transmits());
                    let direct = if mis {
                        let bsdf = |w| {
                            let wi = frame.to_local(w);
                            let shared = material.eval(wo, wi, entering, Transport::Radiance);
                            MisBsdf { alone: Color::ZERO, shared, pdf: material.pdf(wo, wi, entering) }
                        };
                        direct_light_mis(self.scene, &hit, n, bsdf, count, skip, both, None, ctx)
                    } else {
                        let brdf = |w| material.eval(wo, frame.to_local(w), entering, Transport::Radiance);
                        direct_light(self.scene, &hit, n, brdf, count, skip, both, None, ctx)
                    };
                    radiance += throughput * ctx.checked(direct, "path direct");
                }
                let Some(s) = material.sample(wo, entering, Transport::Radiance, ctx.rng) else { break };
                shared = (mis && s.lobe != Lobe::Specular).then(|| BsdfSample {
                    point: hit.point,
                    normal: n,
                    pdf: material.pdf(wo, s.wi, entering),
                    shadow_rays: self.shadow_rays,
                    compensated: false,
                });
                s
            };
            let dir = frame.to_world(scatter.wi).normalize();
            if hit.shading_normal != hit.normal && !hit.leaves_as(ray.dir, dir, scatter.wi.z > 0.0) {
                break;
            }
            if scatter.lobe == Lobe::Specular {
                count_emission = true;
            } else {
                count_emission = false;
                specular_chain = false;
            }
            throughput *= scatter.weight;
            if depth >= RR_DEPTH {
                let q = max_component(throughput).min(0.95);
                if !(ctx.rng.random::<f32>() < q) {
                    break;
                }
                throughput /= q;
            }
            if max_component(throughput) <= 0.0 {
                break;
            }
            let (next, dep) = hit.spawn(dir);
            (ray, departure) = (next, Some(dep));
        }
        radiance
    }
}
