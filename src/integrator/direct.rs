//! Direct light: shadow rays to samples of the lights.

use super::mis::power_heuristic;
use super::photon::gather::GatherSequence;
use super::Context;
use crate::light::{Incident, Light};
use crate::math::{Color, Ray};
use crate::sampling::{next_2d, stratified_2d};
use crate::scene::{Hit, Scene};
use glam::Vec3;
use rand::RngExt;
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
/// With `points` (a camera vertex's: its pixel's sequence, continued over
/// the pixel's samples and passes), sample `s` of each light is the
/// sequence's point `s` instead of a random point in stratum `s`: the
/// pixel's shadow rays stay stratified over the light across its samples
/// and passes, where points drawn anew add independent noise (a penumbra
/// converges as fast as the gather rays' light). Each point on its own is
/// uniform: the mean is the same. A scene of many lights, whose draws pick
/// a light each, draws its points at random.
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
    points: Option<&GatherSequence>,
    ctx: &mut Context,
) -> Color {
    let points = points.filter(|_| !scene.many_lights());
    each_light(scene, hit, n, count, skip, ctx, |light, count, _, ctx| {
        let mut sum = Color::ZERO;
        for s in (0..count).step_by(2) {
            let mut pair = [None; 2];
            for (j, slot) in pair.iter_mut().enumerate().take((count - s) as usize) {
                let u = light_point(points, s + j as u32, count, ctx);
                *slot = light
                    .sample_li(hit.point, n, u)
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
    points: Option<&GatherSequence>,
    ctx: &mut Context,
) -> Color {
    direct_light_weighted(scene, hit, n, bsdf, count, skip, both_sides, false, points, ctx)
}

/// [`direct_light_mis`] where the continuation's strategy draws every
/// direction of the hemisphere (final gathering's cosine rays): the lights
/// draw their shadow rays by `Source::sample_li_shared`, an environment
/// map from its parts brighter than its mean (MIS compensation).
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub fn direct_light_shared(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    bsdf: impl Fn(Vec3) -> MisBsdf,
    count: u32,
    skip: bool,
    both_sides: bool,
    points: Option<&GatherSequence>,
    ctx: &mut Context,
) -> Color {
    direct_light_weighted(scene, hit, n, bsdf, count, skip, both_sides, true, points, ctx)
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn direct_light_weighted(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    bsdf: impl Fn(Vec3) -> MisBsdf,
    count: u32,
    skip: bool,
    both_sides: bool,
    shared: bool,
    points: Option<&GatherSequence>,
    ctx: &mut Context,
) -> Color {
    let points = points.filter(|_| !scene.many_lights());
    each_light(scene, hit, n, count, skip, ctx, |light, count, share, ctx| {
        let mut sum = Color::ZERO;
        for s in 0..count {
            let u = light_point(points, s, count, ctx);
            let sample =
                if shared { light.sample_li_shared(hit.point, n, u) } else { light.sample_li(hit.point, n, u) };
            let Some(inc) = sample else { continue };
            let cos_x = n.dot(inc.dir);
            if facing(cos_x, both_sides) && reaches(hit, n, inc.dir, cos_x > 0.0) && unshadowed(scene, hit, &inc, ctx) {
                let f = bsdf(inc.dir);
                let w = if light.is_delta() {
                    1.0
                } else if shared {
                    power_heuristic(share, light.pdf_li_shared(hit.point, n, inc.dir), 1.0, f.pdf)
                } else {
                    power_heuristic(share, light.pdf_li_of(hit.point, n, &inc), 1.0, f.pdf)
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
    PI * direct_light(scene, &hit, n, brdf, count, skip, false, None, ctx)
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
    points: Option<&GatherSequence>,
    ctx: &mut Context,
) -> Color {
    let points = points.filter(|_| !scene.many_lights());
    each_light(scene, hit, n, count, skip, ctx, |light, count, _, ctx| {
        let mut sum = Color::ZERO;
        for s in 0..count {
            let u = light_point(points, s, count, ctx);
            let Some(inc) = light.sample_li(hit.point, n, u) else { continue };
            let cos_x = n.dot(inc.dir);
            if facing(cos_x, both_sides) && reaches(hit, n, inc.dir, cos_x > 0.0) && unshadowed(scene, hit, &inc, ctx) {
                sum += brdf(inc.dir) * inc.intensity * cos_x.abs();
            }
        }
        sum
    })
}

/// Sample `s` of `count` of a light: the sequence's point `s`, or a random
/// point in stratum `s`.
#[inline(always)]
fn light_point(points: Option<&GatherSequence>, s: u32, count: u32, ctx: &mut Context) -> glam::Vec2 {
    match points {
        Some(q) => q.point(s),
        None => stratified_2d(s, count, next_2d(ctx.rng)),
    }
}

/// The sum over the scene's lights of `per_light(light, samples, share)`
/// divided by its samples, skipping (and counting) lights that face away.
/// `share` is what the light's own sampling density is multiplied by in
/// the density of all shadow rays at the point (for MIS,
/// [`Scene::light_share`]). A scene of many lights
/// ([`Scene::many_lights`]) draws [`crate::light::draws`]`(count)` lights
/// from the light hierarchy instead of visiting each, one sample each,
/// weighted by the chance of the draw at the point.
fn each_light(
    scene: &Scene,
    hit: &Hit,
    n: Vec3,
    count: u32,
    skip: bool,
    ctx: &mut Context,
    mut per_light: impl FnMut(&Light, u32, f32, &mut Context) -> Color,
) -> Color {
    let mut sum = Color::ZERO;
    if scene.many_lights() {
        let draws = crate::light::draws(count);
        for k in 0..draws {
            // One draw in each of `draws` equal parts of [0, 1): the choices
            // spread over the lights as their chances say.
            let u = (k as f64 + ctx.rng.random::<f64>()) / draws as f64;
            let Some((index, p)) = scene.sample_light(hit.point, n, u) else {
                // No light sends anything here.
                ctx.counters.shadow_rays_skipped += 1;
                continue;
            };
            let light = &scene.lights[index];
            if skip && light.faces_away(hit.point) {
                ctx.counters.shadow_rays_skipped += 1;
                continue;
            }
            let share = draws as f32 * p;
            sum += per_light(light, 1, share, ctx) / share;
        }
        return sum;
    }
    for light in &scene.lights {
        let count = if light.is_delta() { 1 } else { count };
        if skip && light.faces_away(hit.point) {
            ctx.counters.shadow_rays_skipped += count as u64;
            continue;
        }
        sum += per_light(light, count, count as f32, ctx) / count.max(1) as f32;
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
    // The ray stops 1e-4 of its length short of the light: a surface
    // touching the light's own (a neighbour in an emissive mesh, whose
    // boxes every shadow ray to the mesh would otherwise open) is not
    // taken for a blocker.
    let t_max = inc.target.map_or(f32::INFINITY, |p| (p - shadow.origin).length() * (1.0 - 1e-4));
    !scene.occluded(&shadow, Some(dep), t_max, inc.prim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::sampling::{stream, uniform_cone, Domain};
    use crate::scene::Eye;
    use crate::stats::Counters;

    /// With more lights than [`crate::scene::MANY_LIGHTS`], drawing lights
    /// by power gives the light that visiting each gives, in the mean: the
    /// default room with 100 small triangle lights of unequal radiance
    /// under its ceiling, at points of its floor.
    #[test]
    fn drawing_many_lights_from_the_hierarchy_keeps_the_mean() {
        use crate::light::{AreaLight, Emitting};
        use crate::scene::Scene;
        use crate::shape::Triangle;
        let mut parts = Scene::tncg15_parts(Eye::One);
        for i in 0..100 {
            let (x, y) = (1.0 + (i % 10) as f32, -4.5 + (i / 10) as f32);
            let v = |dx: f32, dy: f32| glam::Vec3::new(x + dx, y + dy, 4.9);
            // Wound to face down, into the room.
            let t = Triangle::new(v(0.0, 0.0), v(0.0, 0.3), v(0.3, 0.0));
            let radiance = Color::splat(1.0 + (i % 7) as f32);
            parts.lights.push(AreaLight::unplaced(Emitting::Triangle(t), radiance, None));
        }
        let scene = Scene::from_parts(parts);
        assert!(scene.many_lights());
        let brdf = |_: Vec3| Color::splat(0.8 / std::f32::consts::PI);
        for (k, x) in [Vec3::new(3.0, 0.0, -4.99), Vec3::new(8.0, 2.0, -4.99)].into_iter().enumerate() {
            let hit = scene.intersect(&Ray::new(x + Vec3::Z * 0.005, -Vec3::Z), None).unwrap();
            let n = Vec3::Z;
            let (mut counters, mut rng) = (Counters::default(), stream(21, Domain::Camera, k as u64));
            let mut ctx = Context { rng: &mut rng, counters: &mut counters, pixel: 0 };
            // Drawn by power: 40,000 estimates of 4 draws.
            let runs = 40_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..runs {
                let e = direct_light(&scene, &hit, n, brdf, 4, false, false, None, &mut ctx).x as f64;
                sum += e;
                sum2 += e * e;
            }
            let mean = sum / runs as f64;
            let se = ((sum2 / runs as f64 - mean * mean) / runs as f64).sqrt();
            // Each light visited: 20,000 stratified samples of each (at
            // 2,000 the disk light's penumbra under the triangles alone
            // was off by 0.5%).
            let mut want = 0.0f64;
            for light in &scene.lights {
                let m = 20_000;
                let mut acc = 0.0f64;
                for s in 0..m {
                    let u = stratified_2d(s, m, next_2d(ctx.rng));
                    if let Some(inc) = light.sample_li(hit.point, n, u) {
                        let c = n.dot(inc.dir);
                        if c > 0.0 && unshadowed(&scene, &hit, &inc, &mut ctx) {
                            acc += (brdf(inc.dir) * inc.intensity * c).x as f64;
                        }
                    }
                }
                want += acc / m as f64;
            }
            assert!((mean - want).abs() < 4.0 * se + 2e-3 * want, "point {k}: {mean} ± {se} vs {want}");
        }
    }

    /// Shadow rays whose points a pixel's sequence gives keep the mean of
    /// random points, and a pixel's samples together find its light more
    /// closely: at points of the default room that see part of the light
    /// (behind its objects' edges), 256 samples of 2 rays each against
    /// 8192 random ones.
    #[test]
    fn points_from_a_sequence_keep_the_mean_and_cut_the_error() {
        let scene = Scene::tncg15(Eye::One);
        let brdf = |_: Vec3| Color::splat(0.8 / std::f32::consts::PI);
        let (samples, truth_samples, count) = (256u64, 8192u64, 2);
        let (mut bias, mut var, mut err_seq, mut err_rand, mut partly_lit) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0);
        let mut rng = stream(17, Domain::Camera, 0);
        for i in 0..20_000u64 {
            if partly_lit == 60 {
                break;
            }
            let dir = uniform_cone(next_2d(&mut rng), -1.0);
            let Some(hit) = scene.intersect(&Ray::new(glam::Vec3::new(5.0, 0.0, 0.0), dir), None) else { continue };
            let n = hit.facing_normal(dir);
            let (mut counters, mut r) = (Counters::default(), stream(23, Domain::Camera, i));
            let mut ctx = Context { rng: &mut r, counters: &mut counters, pixel: i };
            let estimate = |q: Option<&GatherSequence>, ctx: &mut Context| {
                direct_light(&scene, &hit, n, brdf, count, true, false, q, ctx).x as f64
            };
            // Points wholly lit or wholly dark have no noise to cut.
            let probe: Vec<f64> = (0..64).map(|_| estimate(None, &mut ctx)).collect();
            if probe.iter().all(|&e| e == probe[0]) {
                continue;
            }
            partly_lit += 1;
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..truth_samples {
                let e = estimate(None, &mut ctx);
                sum += e;
                sum2 += e * e;
            }
            let truth = sum / truth_samples as f64;
            let v = sum2 / truth_samples as f64 - truth * truth;
            let scramble = crate::sampling::splitmix64(i);
            let seq = (0..samples)
                .map(|index| estimate(Some(&GatherSequence::new(index, scramble, count)), &mut ctx))
                .sum::<f64>()
                / samples as f64;
            let rand = (0..samples).map(|_| estimate(None, &mut ctx)).sum::<f64>() / samples as f64;
            bias += seq - truth;
            var += v / samples as f64 + v / truth_samples as f64;
            err_seq += (seq - truth).powi(2);
            err_rand += (rand - truth).powi(2);
        }
        assert_eq!(partly_lit, 60, "partly lit points found");
        assert!(bias.abs() < 4.0 * var.sqrt(), "summed bias {bias} vs se {}", var.sqrt());
        assert!(err_seq < 0.5 * err_rand, "squared error {err_seq} from the sequence vs {err_rand} random");
    }

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
            let a = run(&|ctx| direct_light(&scene, &hit, n, brdf, count, true, false, None, ctx));
            let b = run(&|ctx| direct_light_one_at_a_time(&scene, &hit, n, brdf, count, true, false, None, ctx));
            assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "point {i}");
            checked += (a != Color::ZERO) as u32;
        }
        assert!(checked > 1000, "{checked} lit points");
    }
}
