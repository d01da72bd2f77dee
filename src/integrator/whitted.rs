//! The Whitted ray tracer of the CS475 assignment (`traceRay`): Phong
//! shading with the course's formula, a shadow ray per light sample, and
//! recursive mirror bounces (and glass, split by Fresnel) to a depth limit.
//!
//! rho = m_a C A + sum over unshadowed lights of
//!       (m_l C I max(l . n, 0) + m_s S I max(r . v, 0)^m_sp)
//!       + m_r C traceRay(reflected ray, depth + 1)
//!
//! with `I` the light's colour dimmed by 1 / (d + d0)^falloff (point
//! lights), undimmed (directional lights), or L cos_l A / d^2 per sample
//! (area lights, averaged over a fixed stratified set of samples). A
//! Lambertian material of reflectance rho is read as m_l = 1 / pi, C = rho,
//! m_a = 1: its direct light is then exactly photonmap's.

use crate::material::{Material, Phong, Transport};
use crate::math::{max_component, Color, Frame, Ray};
use crate::optics::reflect;
use crate::sampling::{next_2d, stratified_2d, Rng};
use crate::scene::{Hit, Scene};
use crate::shape::Departure;

use super::{Context, Integrator, Part};

/// Shadow-ray samples per area light per shaded point (the course's lights
/// are points; area lights get a soft shadow from this many samples).
const AREA_SAMPLES: u32 = 16;

pub struct Whitted<'a> {
    pub scene: &'a Scene,
    /// Bounce rays stop after this many reflections (0: none).
    pub max_depth: u32,
}

impl Whitted<'_> {
    /// The colour seen along `ray` (the course's `traceRay`).
    pub fn trace_ray(&self, ray: &Ray, departure: Option<Departure>, depth: u32, rng: &mut Rng) -> Color {
        let Some(hit) = self.scene.intersect(ray, departure) else {
            return Color::ZERO;
        };
        let through = self.scene.transmittance(departure, hit.t);
        let material = &self.scene.material_seen(&hit, ray.dir);
        let (frame, entering) = hit.scattering_frame(ray.dir, material);
        let shaded = match material.course_phong() {
            Some(p) => self.phong(&hit, ray, &frame, &p, depth, rng),
            None => self.specular(&hit, ray, &frame, entering, material, depth, rng),
        };
        // A light's own surface, or a glowing one.
        through * (self.scene.emitted(&hit, ray.dir) + shaded)
    }

    /// Mirrors and glass: every branch (Fresnel's shares for glass) traced
    /// on, to the depth limit.
    #[allow(clippy::too_many_arguments)]
    fn specular(
        &self,
        hit: &Hit,
        ray: &Ray,
        frame: &Frame,
        entering: bool,
        material: &Material,
        depth: u32,
        rng: &mut Rng,
    ) -> Color {
        if depth >= self.max_depth {
            return Color::ZERO;
        }
        let mut c = Color::ZERO;
        for b in material.specular_branches(frame.to_local(-ray.dir), entering, Transport::Radiance).iter() {
            let (next, dep) = hit.spawn(frame.to_world(b.wi).normalize());
            c += b.prob * b.scale * self.trace_ray(&next, Some(dep), depth + 1, rng);
        }
        c
    }

    /// The bounce ray: `ray` reflected about the normal, if depth allows.
    fn bounce(&self, hit: &Hit, ray: &Ray, frame: &Frame, depth: u32, rng: &mut Rng) -> Color {
        if depth >= self.max_depth {
            return Color::ZERO;
        }
        let (next, dep) = hit.spawn(frame.to_world(reflect(frame.to_local(-ray.dir))).normalize());
        self.trace_ray(&next, Some(dep), depth + 1, rng)
    }

    fn phong(&self, hit: &Hit, ray: &Ray, frame: &Frame, p: &Phong, depth: u32, rng: &mut Rng) -> Color {
        let n = frame.n;
        let v = -ray.dir;
        let mut c = p.ambient * p.color * self.scene.ambient;
        let highlight = p.specular * p.highlight();
        for light in &self.scene.lights {
            let count = if light.is_delta() { 1 } else { AREA_SAMPLES };
            let mut sum = Color::ZERO;
            for s in 0..count {
                let Some(inc) = light.sample_li(hit.point, n, stratified_2d(s, count, next_2d(rng))) else {
                    continue;
                };
                let cos = inc.dir.dot(n);
                // Above the shading normal, and above the actual surface.
                if !(cos > 0.0) || !hit.leaves_as(-n, inc.dir, true) {
                    continue;
                }
                // Shadows: a point light only counts blockers before it, a
                // directional light any blocker along the ray.
                let (shadow, dep) = hit.spawn(inc.dir);
                let t_max = inc.target.map_or(f32::INFINITY, |q| (q - shadow.origin).length());
                if self.scene.occluded(&shadow, Some(dep), t_max, inc.prim) {
                    continue;
                }
                sum += inc.intensity * (p.diffuse * p.color * cos + highlight * p.highlight_factor(n, inc.dir, v));
            }
            c += sum / count as f32;
        }
        if p.mirror > 0.0 && max_component(p.color) > 0.0 {
            c += p.mirror * p.color * self.bounce(hit, ray, frame, depth, rng);
        }
        c
    }
}

impl Integrator for Whitted<'_> {
    type Thread = ();
    type Pixel = ();

    /// The course's `traceRay` (it has no separate emitted part: the camera
    /// pass asks it for everything).
    fn radiance(&self, ray: Ray, _: Part, ctx: &mut Context, _: &mut (), _: &mut ()) -> Color {
        ctx.counters.rays += 1;
        let c = self.trace_ray(&ray, None, 0, ctx.rng);
        ctx.checked(c, "whitted")
    }
}
