//! Path tracing with next-event estimation (the course's grade-3/4 renderer),
//! unbiased: the project's own reference.
//!
//! At each diffuse vertex, direct light is estimated by a shadow ray to the
//! lights; a path that then reaches a light after a diffuse bounce adds
//! nothing (that light was already counted). Emission is counted on camera
//! rays and after mirror or glass bounces, whose delta lobes a shadow ray
//! cannot sample. Mirror and glass are sampled (Fresnel chooses the branch);
//! Russian roulette on the path's throughput ends long paths without bias.

use super::{direct_light, glass_branches, Context, Integrator, Part};
use crate::material::{Lobe, Material};
use crate::math::{max_component, Color, Frame, Ray};
use crate::sampling::{cosine_hemisphere, next_2d};
use crate::scene::Scene;
use rand::RngExt;
use std::f32::consts::PI;

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
}

impl Integrator for PathIntegrator<'_> {
    type Thread = ();
    type Pixel = ();

    fn radiance(&self, ray: Ray, part: Part, ctx: &mut Context, _: &mut (), _: &mut ()) -> Color {
        let mut radiance = Color::ZERO;
        let mut throughput = Color::ONE;
        let (mut ray, mut departure) = (ray, None);
        // Whether a light met now is counted: on camera rays and after specular bounces.
        let mut count_emission = true;
        // Whether every vertex so far was specular (the path is E S* so far).
        let mut specular_chain = true;
        for depth in 0..MAX_DEPTH {
            ctx.counters.rays += 1;
            let Some(hit) = self.scene.intersect(&ray, departure) else { break };
            throughput *= self.scene.transmittance(departure, hit.t);
            let material = *self.scene.material(hit.prim);
            let wanted = match part {
                Part::All => true,
                Part::Emitted => specular_chain,
                Part::Reflected => !specular_chain,
            };
            if material != Material::Emitter && count_emission && wanted {
                // A glowing surface's own light; after a diffuse bounce the
                // shadow rays counted it.
                radiance += throughput * self.scene.emitted(hit.prim, ray.dir);
            }
            let wo = match material {
                Material::Emitter => {
                    let wanted = match part {
                        Part::All => true,
                        Part::Emitted => specular_chain,
                        Part::Reflected => !specular_chain,
                    };
                    if count_emission && wanted {
                        if let Some(light) = self.scene.light_of(hit.prim) {
                            radiance += throughput * light.radiance_towards(ray.dir);
                        }
                    }
                    break;
                }
                Material::Lambertian { rho } => {
                    if part == Part::Emitted || max_component(rho) <= 0.0 {
                        break;
                    }
                    let n = hit.facing_normal(ray.dir);
                    let direct = direct_light(self.scene, &hit, n, |_| rho / PI, self.shadow_rays, self.skip, ctx);
                    radiance += throughput * ctx.checked(direct, "path direct");
                    count_emission = false;
                    specular_chain = false;
                    // Cosine sampling: f cos / pdf = rho.
                    throughput *= rho;
                    Frame::from_normal(n).to_world(cosine_hemisphere(next_2d(ctx.rng)))
                }
                Material::Phong(p) => {
                    let n = hit.facing_normal(ray.dir);
                    if part == Part::Emitted {
                        // Only the mirror lobe continues a specular chain.
                        if p.mirror <= 0.0 {
                            break;
                        }
                        throughput *= p.mirror_rho();
                        hit.mirrored(ray.dir)
                    } else {
                        let to_viewer = -ray.dir;
                        let direct = direct_light(
                            self.scene,
                            &hit,
                            n,
                            |w| p.brdf(n, w, to_viewer),
                            self.shadow_rays,
                            self.skip,
                            ctx,
                        );
                        radiance += throughput * ctx.checked(direct, "path direct");
                        let Some((lobe, prob)) = p.choose_lobe(ctx.rng.random::<f32>()) else { break };
                        match lobe {
                            Lobe::Mirror => {
                                count_emission = true;
                                throughput *= p.mirror_rho() / prob;
                                hit.mirrored(ray.dir)
                            }
                            Lobe::Diffuse => {
                                count_emission = false;
                                specular_chain = false;
                                throughput *= p.diffuse_rho() / prob;
                                Frame::from_normal(n).to_world(cosine_hemisphere(next_2d(ctx.rng)))
                            }
                            Lobe::Glossy => {
                                count_emission = false;
                                specular_chain = false;
                                let Some((dir, w)) = p.sample_glossy(n, to_viewer, next_2d(ctx.rng)) else { break };
                                throughput *= w / prob;
                                dir
                            }
                        }
                    }
                }
                Material::Mirror { reflectance } => {
                    throughput *= reflectance;
                    count_emission = true;
                    hit.mirrored(ray.dir)
                }
                Material::Glass { ior, .. } => {
                    count_emission = true;
                    let b = glass_branches(&hit, &ray, ior);
                    match b.refracted {
                        Some((wt, scale)) if ctx.rng.random::<f32>() >= b.fresnel => {
                            throughput *= scale;
                            wt
                        }
                        _ => b.reflected,
                    }
                }
            };
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
            let (next, dep) = hit.spawn(wo.normalize());
            (ray, departure) = (next, Some(dep));
        }
        radiance
    }
}
