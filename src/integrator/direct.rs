//! Direct light: shadow rays to samples of the lights.

use super::mis::power_heuristic;
use super::Context;
use crate::light::{Incident, Light};
use crate::math::{Color, Ray};
use crate::sampling::{next_2d, stratified_2d};
use crate::scene::{Hit, Scene};
use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, PI};

/// Light reflected at a surface point straight from the lights:
/// sum over lights of f(w) I cos_x, averaged over `count` stratified samples
/// of each area light (one sample of a point or directional light is exact),
/// each with a shadow ray. `brdf(w)` is the BRDF for light arriving from
/// unit `w` (towards the light); `n` is the normal on the viewer's side.
/// With `skip`, a light whose emitting side faces away from the point (a
/// one-sided area light seen from behind or edge-on, where every sample has
/// cos_l <= 0) is not sampled. With `both_sides` (a surface that lets
/// light through, rough glass), lights behind the surface count too, by
/// |cos|.
///
/// The samples are taken two at a time: both are drawn before either
/// shadow ray is cast, so the processor works out the second (a chain of a
/// division, a square root and another division) while the first ray is
/// traced (path-traced passes 9-11% faster, notes/performance.md). The
/// random numbers are drawn and the terms summed in the same order as
/// [`direct_light_one_at_a_time`], the plain version, so the two agree to
/// the bit (tested below).
#[allow(clippy::too_many_arguments)]
pub fn direct_light(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    brdf: impl Fn(Vec3) -> Color,
    count: u32,
    skip: bool,
    both_sides: bool,
    ctx: &mut Context,
) -> Color {
    each_light(scene, hit, count, skip, ctx, |light, count, ctx| {
        let mut sum = Color::ZERO;
        for s in (0..count).step_by(2) {
            let mut pair = [None; 2];
            for (j, slot) in pair.iter_mut().enumerate().take((count - s) as usize) {
                let u = stratified_2d(s + j as u32, count, next_2d(ctx.rng));
                *slot = light
                    .incident_around(hit.point, n, u)
                    .map(|inc| (n.dot(inc.dir), inc))
                    .filter(|&(c, inc)| facing(c, both_sides) && reaches(hit, n, inc.dir, c > 0.0));
            }
            for (cos_x, inc) in pair.into_iter().flatten() {
                if unshadowed(scene, hit, &inc, ctx) {
                    sum += brdf(inc.dir) * inc.intensity * cos_x.abs();
                }
            }
        }
        sum
    })
}

/// What a vertex's BSDF answers for a direction towards a light, for
/// [`direct_light_mis`].
#[derive(Clone, Copy, Debug)]
pub struct MisBsdf {
    /// The part of the BSDF only shadow rays estimate (a plastic's diffuse
    /// base, where the continuation samples the coat alone).
    pub alone: Color,
    /// The part also estimated by the continuation's sample.
    pub shared: Color,
    /// The density with which the continuation draws the direction.
    pub pdf: f32,
}

/// [`direct_light`] at a vertex whose continuation is also sampled for the
/// light it meets (notes/method.md, §7): each shadow ray's `shared` part
/// weighted by the power heuristic against the BSDF's density
/// ([`super::mis`]), the `alone` part in full. Delta lights, which no
/// sampled direction meets, keep the weight one. One sample at a time.
/// Never inlined: the loops that call it at every vertex (final
/// gathering's) stay as small as they were for scenes without glossy lobes.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub fn direct_light_mis(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    bsdf: impl Fn(Vec3) -> MisBsdf,
    count: u32,
    skip: bool,
    both_sides: bool,
    ctx: &mut Context,
) -> Color {
    each_light(scene, hit, count, skip, ctx, |light, count, ctx| {
        let mut sum = Color::ZERO;
        for s in 0..count {
            let u = stratified_2d(s, count, next_2d(ctx.rng));
            let Some(inc) = light.incident_around(hit.point, n, u) else { continue };
            let cos_x = n.dot(inc.dir);
            if facing(cos_x, both_sides) && reaches(hit, n, inc.dir, cos_x > 0.0) && unshadowed(scene, hit, &inc, ctx) {
                let f = bsdf(inc.dir);
                let w = if light.is_delta() {
                    1.0
                } else {
                    power_heuristic(count as f32, light.pdf_of(hit.point, n, &inc), 1.0, f.pdf)
                };
                sum += (f.alone + f.shared * w) * inc.intensity * cos_x.abs();
            }
        }
        sum
    })
}

/// Irradiance at `x`, a point on a surface facing `n` (towards the side
/// light arrives on), straight from the lights: [`direct_light`] of a
/// Lambertian surface of reflectance 1, times pi. The surface is found
/// by a short ray down onto it (zero where there is none).
pub fn direct_irradiance(scene: &Scene, x: Vec3, n: Vec3, count: u32, skip: bool, ctx: &mut Context) -> Color {
    let height = 1e-4 * (1.0 + x.abs().max_element());
    let Some(hit) = scene.intersect(&Ray::new(x + height * n, -n), None) else {
        return Color::ZERO;
    };
    if hit.t > 2.0 * height {
        return Color::ZERO;
    }
    let brdf = |_: Vec3| Color::splat(FRAC_1_PI);
    PI * direct_light(scene, &hit, n, brdf, count, skip, false, ctx)
}

/// [`direct_light`] one sample at a time: the reference it must equal.
#[allow(clippy::too_many_arguments)]
pub fn direct_light_one_at_a_time(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    brdf: impl Fn(Vec3) -> Color,
    count: u32,
    skip: bool,
    both_sides: bool,
    ctx: &mut Context,
) -> Color {
    each_light(scene, hit, count, skip, ctx, |light, count, ctx| {
        let mut sum = Color::ZERO;
        for s in 0..count {
            let u = stratified_2d(s, count, next_2d(ctx.rng));
            let Some(inc) = light.incident_around(hit.point, n, u) else { continue };
            let cos_x = n.dot(inc.dir);
            if facing(cos_x, both_sides) && reaches(hit, n, inc.dir, cos_x > 0.0) && unshadowed(scene, hit, &inc, ctx) {
                sum += brdf(inc.dir) * inc.intensity * cos_x.abs();
            }
        }
        sum
    })
}

/// The sum over the scene's lights of `per_light(light, samples)` divided
/// by its samples, skipping (and counting) lights that face away.
fn each_light(
    scene: &Scene,
    hit: &Hit,
    count: u32,
    skip: bool,
    ctx: &mut Context,
    mut per_light: impl FnMut(&Light, u32, &mut Context) -> Color,
) -> Color {
    let mut sum = Color::ZERO;
    for light in &scene.lights {
        let count = if light.is_delta() { 1 } else { count };
        if skip && light.faces_away(hit.point) {
            ctx.counters.shadow_rays_skipped += count as u64;
            continue;
        }
        sum += per_light(light, count, ctx) / count.max(1) as f32;
    }
    sum
}

/// Whether light from a direction of cosine `cos` with the normal counts:
/// from above, or from either side where the surface lets light through.
#[inline(always)]
fn facing(cos: f32, both_sides: bool) -> bool {
    cos > 0.0 || (both_sides && cos < 0.0)
}

/// Whether light from `dir` can reach the surface's side `n` faces (or,
/// `above` false, its other side): the side of the shading normal is not
/// enough where it differs from the geometric one (light from the far
/// side of the actual surface would leak through it).
#[inline]
fn reaches(hit: &Hit, n: Vec3, dir: Vec3, above: bool) -> bool {
    hit.shading_normal == hit.normal || hit.leaves_as(-n, dir, above)
}

/// Casts the shadow ray from `hit` towards a light sample: whether nothing
/// but the light itself blocks it.
#[inline]
fn unshadowed(scene: &Scene, hit: &Hit, inc: &Incident, ctx: &mut Context) -> bool {
    let (shadow, dep) = hit.spawn(inc.dir);
    ctx.counters.rays += 1;
    let t_max = inc.target.map_or(f32::INFINITY, |p| (p - shadow.origin).length());
    !scene.occluded(&shadow, Some(dep), t_max, inc.prim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::sampling::{stream, uniform_cone, Domain};
    use crate::scene::Eye;
    use crate::stats::Counters;

    /// The paired samples equal the plain loop to the bit, at diffuse
    /// points all over the default room, for odd and even sample counts.
    #[test]
    fn paired_samples_equal_the_plain_loop() {
        let scene = Scene::tncg15(Eye::One);
        let mut rng = stream(5, Domain::Camera, 0);
        let mut checked = 0;
        for i in 0..3000u64 {
            let dir = uniform_cone(next_2d(&mut rng), -1.0);
            let Some(hit) = scene.intersect(&Ray::new(glam::Vec3::new(5.0, 0.0, 0.0), dir), None) else { continue };
            let n = hit.facing_normal(dir);
            let brdf = |_: Vec3| Color::splat(0.8 / std::f32::consts::PI);
            let count = 1 + (i % 4) as u32;
            let run = |f: &dyn Fn(&mut Context) -> Color| {
                let (mut r, mut counters) = (stream(9, Domain::Camera, i), Counters::default());
                f(&mut Context { rng: &mut r, counters: &mut counters, pixel: i })
            };
            let a = run(&|ctx| direct_light(&scene, &hit, n, brdf, count, true, false, ctx));
            let b = run(&|ctx| direct_light_one_at_a_time(&scene, &hit, n, brdf, count, true, false, ctx));
            assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "point {i}");
            checked += (a != Color::ZERO) as u32;
        }
        assert!(checked > 1000, "{checked} lit points");
    }
}
