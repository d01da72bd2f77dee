//! The photon pass: emit, follow mirrors and glass, store at diffuse
//! surfaces, continue by Russian roulette.
//!
//! Every photon draws from its own random stream keyed by (seed, pass,
//! photon index), and photons are traced in fixed-size blocks kept in block
//! order, a block's photons interleaved in a fixed schedule, so the maps
//! are identical whatever the number of threads.

use super::aims::{specular_targets, Target};
use super::guide::{EmissionGuide, Stored};
use super::{Photon, PhotonBlocks};
use crate::light::Aim;
use crate::material::{Lobe, Transport};
use crate::math::{max_component, Color, Frame, Ray};
use crate::sampling::{concentric_disk, next_2d, photon_points, stream, uniform_cone, uniform_cone_pdf, Domain, Rng};
use crate::scene::Scene;
use crate::shape::Departure;
use glam::{Vec2, Vec3};
use rand::RngExt;
use rayon::prelude::*;
use std::f32::consts::PI;

/// Photons are traced in blocks of this many; each block is one rayon task.
const BLOCK: u64 = 4096;
/// A photon path is cut after this many bounces. Russian roulette ends
/// diffuse paths long before; only light trapped by total internal
/// reflection could go on, carrying a negligible share of the power.
const MAX_BOUNCES: u32 = 64;

/// Which of the two passes a photon belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    Global,
    Caustic,
}

/// The photons of one pass and what it cost.
#[derive(Debug, Default)]
pub struct PassOutput {
    pub photons: PhotonBlocks,
    pub emitted: u64,
    /// Rays cast (one per segment of every photon path).
    pub rays: u64,
    /// Emitted photons whose first hit was a specular object (caustic pass:
    /// the aiming efficiency).
    pub first_hit_specular: u64,
    /// Caustic pass: per target ([`specular_targets`]), the photons
    /// aimed at it and those of them whose first hit was mirror or glass.
    pub aimed: Vec<[u64; 2]>,
    /// Emitted photons whose first ray met the scene.
    pub landed: u64,
}

/// What the tracing of a block counted.
#[derive(Debug, Default, PartialEq)]
struct Tally {
    rays: u64,
    first_specular: u64,
    aimed: Vec<[u64; 2]>,
    landed: u64,
}

/// Traces `n` photons of `pass`; `on_block` is told the number of photons
/// done after each block (for progress bars).
pub fn trace_pass(scene: &Scene, pass: Pass, n: u64, seed: u64, on_block: &(dyn Fn(u64) + Sync)) -> PassOutput {
    trace_pass_with(scene, &specular_targets(scene), pass, n, seed, Sequence { seed, first: 0 }, on_block)
}

/// [`trace_pass`] with the scene's caustic targets found already
/// ([`specular_targets`]).
pub fn trace_pass_with(
    scene: &Scene,
    targets: &[Target],
    pass: Pass,
    n: u64,
    seed: u64,
    sequence: Sequence,
    on_block: &(dyn Fn(u64) + Sync),
) -> PassOutput {
    // Lights that emit nothing emit no photons (choosing among them by power
    // would divide zero by zero).
    let emits = max_component(scene.emitted_power()) > 0.0;
    if n == 0 || !emits || (pass == Pass::Caustic && targets.is_empty()) {
        return PassOutput { emitted: n, ..PassOutput::default() };
    }
    let domain = match pass {
        Pass::Global => Domain::GlobalPhotons,
        Pass::Caustic => Domain::CausticPhotons,
    };
    // Light at infinity sends the global pass's photons where the camera
    // sees their light (`guide`), and the pass emits as many as that
    // makes n count (`photons_to_emit`).
    let guide = match pass {
        Pass::Global => EmissionGuide::build(scene, false, seed, &|ray, departure, power, rng| {
            pilot_photon(scene, ray, departure, power, rng)
        }),
        Pass::Caustic => None,
    };
    let asked = n;
    let n = match pass {
        Pass::Global => photons_to_emit(scene, n, guide.as_ref(), seed),
        Pass::Caustic => n,
    };
    let guide = guide.as_ref();
    let blocks = n.div_ceil(BLOCK);
    let per_block: Vec<(Vec<Photon>, Tally)> = (0..blocks)
        .into_par_iter()
        // Each thread traces into a buffer that has reached the size of its
        // blocks (a fresh vector per block grew, copied and faulted its way
        // to ~20,000 photons) and hands the buffer itself out, not a copy;
        // the next block starts in a fresh one of that capacity, whose pages
        // are faulted in only as photons are written.
        .map_init(Vec::new, |out: &mut Vec<Photon>, b| {
            let (start, end) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
            let tally = trace_range::<LANES>(scene, targets, pass, n, seed, sequence, guide, domain, start..end, out);
            // Progress in the photons asked for.
            let asked_by = |i: u64| (i as u128 * asked as u128 / n as u128) as u64;
            on_block(asked_by(end) - asked_by(start));
            let capacity = out.capacity();
            (std::mem::replace(out, Vec::with_capacity(capacity)), tally)
        })
        .collect();
    let mut output = PassOutput { emitted: n, aimed: vec![[0; 2]; targets.len()], ..Default::default() };
    let mut blocks = Vec::with_capacity(per_block.len());
    for (photons, tally) in per_block {
        blocks.push(photons);
        output.rays += tally.rays;
        output.first_hit_specular += tally.first_specular;
        output.landed += tally.landed;
        for (total, block) in output.aimed.iter_mut().zip(&tally.aimed) {
            total[0] += block[0];
            total[1] += block[1];
        }
    }
    output.photons = PhotonBlocks::new(blocks);
    output
}

/// At most this many times the photons asked for are emitted where most
/// miss the scene.
pub(crate) const MAX_EXTRA: u64 = 16;

/// The least share of a guided global pass's n photons that land where the
/// camera sees their light (notes/method.md §3, "What the photon count
/// means with a guide").
pub(crate) const GUIDED_USEFUL_SHARE: f64 = 0.25;

/// How many photons a global pass asked for `n` emits. Light from
/// everywhere (a sky, an environment map) emits n over the share of its
/// photons whose first ray meets the scene, at most [`MAX_EXTRA`] times n,
/// so that its map holds what n would in a closed scene. A guided pass
/// emits as many as land where the camera sees their light what the
/// natural emission of n would, and at least [`GUIDED_USEFUL_SHARE`] of n
/// there: the photons that land cost little in the camera pass until
/// they are many (the volume grid's cells and the irradiance cache grow
/// with them), and few of them are what makes a window's light noisy.
pub(crate) fn photons_to_emit(scene: &Scene, n: u64, guide: Option<&EmissionGuide>, seed: u64) -> u64 {
    let natural = match lit_from_outside(scene) {
        true => (n as f64 / landing_fraction(scene, seed).max(1.0 / MAX_EXTRA as f64)).ceil(),
        false => n as f64,
    };
    let Some(g) = guide else { return natural as u64 };
    let (useful, guided) = g.useful_shares(|i| scene.light_prob(i));
    let landing = (natural * useful).max(n as f64 * GUIDED_USEFUL_SHARE);
    (landing / guided).min(natural).ceil().max(1.0) as u64
}

/// Follows one pilot photon of the global pass ([`EmissionGuide`]) as the
/// pass would, and returns where it stored photons.
fn pilot_photon(scene: &Scene, ray: Ray, departure: Option<Departure>, power: Color, rng: &mut Rng) -> Stored {
    let mut path = Path {
        ray,
        departure,
        power,
        rng: rng.clone(),
        target: NO_TARGET,
        bounce: 0,
        specular_bounces: 0,
        only_specular_so_far: true,
    };
    let mut out = Vec::new();
    while step(scene, Pass::Global, &mut path, &mut out).0 {}
    out.iter().map(|p| (p.position(), Some(p.surface_normal()))).collect()
}

/// Photons of the pilot that measures what share of a pass lands.
const PILOT: u64 = 4096;

/// Whether light from infinity (a sky, an environment map) lights the
/// scene: its photons come from outside, and some miss everything.
pub(crate) fn lit_from_outside(scene: &Scene) -> bool {
    scene.lights.iter().any(|l| matches!(l, crate::light::Light::Constant(_) | crate::light::Light::Envmap(_)))
}

/// The share of the global pass's photons whose first ray meets the
/// scene, measured on a pilot of its own random streams (indices past any
/// pass's), so the same seed gives the same count.
pub(crate) fn landing_fraction(scene: &Scene, seed: u64) -> f64 {
    let first = u64::MAX - PILOT;
    let landed = (first..first + PILOT)
        .into_par_iter()
        .filter(|&i| {
            let mut rng = stream(seed, Domain::GlobalPhotons, i);
            emit(scene, &[], Pass::Global, PILOT, &mut rng)
                .1
                .is_some_and(|(ray, dep, _)| scene.intersect(&ray, dep).is_some())
        })
        .count();
    landed as f64 / PILOT as f64
}

/// Where a caustic pass's photons lie in its render's low-discrepancy
/// sequence ([`photon_points`]): the sequence's seed and the index of the
/// pass's first photon. A progressive render's passes take one sequence
/// in turn, as a pixel's camera samples do, so that all its photons
/// together, not only each pass's, are spread evenly.
#[derive(Clone, Copy, Debug)]
pub struct Sequence {
    pub seed: u64,
    pub first: u64,
}

/// A photon leaving its light: its ray, the departure and its power.
pub type PhotonStart = (Ray, Option<Departure>, Color);

/// Picks a light in proportion to its power (one light: always it) and
/// starts photon `rng` of `n` from it; for the caustic pass, also the
/// target of `targets` it was aimed at (whether or not the light could
/// send it there).
pub fn emit(
    scene: &Scene,
    targets: &[Target],
    pass: Pass,
    n: u64,
    rng: &mut Rng,
) -> (Option<usize>, Option<PhotonStart>) {
    emit_at(scene, targets, pass, n, None, None, rng)
}

/// As [`emit`], a caustic photon taking the light's part of its start from
/// the points `quasi` where given ([`Source::sample_le_towards_at`]), a
/// global one from `guide` where it serves the light.
///
/// [`Source::sample_le_towards_at`]: crate::light::Source::sample_le_towards_at
pub fn emit_at(
    scene: &Scene,
    targets: &[Target],
    pass: Pass,
    n: u64,
    quasi: Option<[Vec2; 2]>,
    guide: Option<&EmissionGuide>,
    rng: &mut Rng,
) -> (Option<usize>, Option<PhotonStart>) {
    let Some((index, p_light)) = scene.pick_light_index(rng.random::<f32>()) else {
        return (None, None);
    };
    let light = &scene.lights[index];
    let scale = 1.0 / (p_light * n as f32);
    match pass {
        Pass::Global => {
            // The light's natural distribution: each photon carries power /
            // n; the guide's, that divided by its density relative to it.
            let (u_pos, u_dir, w) = match guide.and_then(|g| g.sample(index, rng)) {
                Some(drawn) => drawn,
                None => (next_2d(rng), next_2d(rng), 1.0),
            };
            let e = light.sample_le(u_pos, u_dir);
            let power = light.power() * scale * e.weight * w;
            // One that carries nothing is not traced (nor stored, where it
            // would count among an estimate's k nearest).
            (None, (max_component(power) > 0.0).then_some((e.ray, e.departure, power)))
        }
        Pass::Caustic => {
            let chosen = ((rng.random::<f32>() * targets.len() as f32) as usize).min(targets.len() - 1);
            // The power is what the light sends along the photon divided by
            // the density of the aiming: the mixture over all targets.
            let aim = Aiming { targets, chosen };
            let aimed = match quasi {
                Some(u) => light.sample_le_towards_at(&aim, u, rng),
                None => light.sample_le_towards(&aim, rng),
            };
            (Some(chosen), aimed.map(|a| (a.ray, a.departure, a.intensity * scale / a.pdf)))
        }
    }
}

/// Caustic photons aimed at target `chosen` of `targets`, one chosen
/// uniformly: a direction uniform in the cone of its bounding sphere seen
/// from a point, or a start uniform on the disk it casts across parallel
/// light. Densities are the mixtures over all targets that could have
/// given the same direction or start.
struct Aiming<'a> {
    targets: &'a [Target],
    chosen: usize,
}

impl Aim for Aiming<'_> {
    fn direction_from(&self, origin: Vec3, u: Vec2) -> (Vec3, f32) {
        let (axis, cos_max) = self.targets[self.chosen].cone_from(origin);
        // Unit to rounding without normalising (`Frame::to_world`).
        let dir = Frame::from_normal(axis).to_world(uniform_cone(u, cos_max));
        // The direction lies in the chosen cone by construction (a test
        // could deny it by rounding at the rim and leave a zero pdf); the
        // other cones count where they contain it.
        let pdf = self
            .targets
            .iter()
            .enumerate()
            .map(|(j, t)| {
                if j == self.chosen {
                    return uniform_cone_pdf(cos_max);
                }
                let (a, c) = t.cone_from(origin);
                if dir.dot(a) >= c {
                    uniform_cone_pdf(c)
                } else {
                    0.0
                }
            })
            .sum::<f32>()
            / self.targets.len() as f32;
        (dir, pdf)
    }

    fn origin_across(&self, direction: Vec3, plane: Vec3, u: Vec2) -> (Vec3, f32) {
        let frame = Frame::from_normal(direction);
        let project = |c: Vec3| c - direction * (c - plane).dot(direction);
        let chosen = &self.targets[self.chosen];
        let d = concentric_disk(u) * chosen.radius;
        let origin = project(chosen.center) + frame.s * d.x + frame.t * d.y;
        let pdf = self
            .targets
            .iter()
            .enumerate()
            .map(|(j, t)| {
                let inside = (origin - project(t.center)).length_squared() <= t.radius * t.radius;
                if j == self.chosen || inside {
                    1.0 / (PI * t.radius * t.radius)
                } else {
                    0.0
                }
            })
            .sum::<f32>()
            / self.targets.len() as f32;
        (origin, pdf)
    }
}

/// One photon on its way: what the next segment needs.
struct Path {
    ray: Ray,
    departure: Option<Departure>,
    power: Color,
    rng: Rng,
    /// The target the photon was aimed at ([`NO_TARGET`]: none).
    target: u32,
    bounce: u32,
    specular_bounces: u32,
    only_specular_so_far: bool,
}

const NO_TARGET: u32 = u32::MAX;

/// Photons one thread carries at once. Each segment of a path waits on the
/// one before it (the hit, then the sampled direction, then the offset
/// origin); segments of different photons do not, so the processor can
/// overlap them when they are traced round-robin (5% off the pass; four
/// lanes gained no more: notes/performance.md).
const LANES: usize = 2;

/// Traces photons `range` of `pass`, `L` at a time, storing into `out`.
/// Returns (rays cast, photons whose first hit was specular). One lane is
/// the plain loop, one photon after another: any number of lanes stores the
/// same photons, in another order within the block (tested below).
#[allow(clippy::too_many_arguments)]
fn trace_range<const L: usize>(
    scene: &Scene,
    targets: &[Target],
    pass: Pass,
    n: u64,
    seed: u64,
    sequence: Sequence,
    guide: Option<&EmissionGuide>,
    domain: Domain,
    range: std::ops::Range<u64>,
    out: &mut Vec<Photon>,
) -> Tally {
    let mut next = range.start;
    let mut tally = Tally { aimed: vec![[0; 2]; targets.len()], ..Default::default() };
    // Light from infinity takes its caustic photons' starts from a
    // low-discrepancy sequence (`Source::sample_le_towards_at`); the other
    // lights draw theirs from the photon's stream.
    let quasi = matches!(pass, Pass::Caustic) && !scene.lights_at_infinity().is_empty();
    // The next photon of the range that leaves its light.
    let start = |next: &mut u64, tally: &mut Tally| -> Option<Path> {
        while *next < range.end {
            let mut rng = stream(seed, domain, *next);
            let quasi = quasi.then(|| photon_points(sequence.seed, sequence.first + *next));
            *next += 1;
            let (target, emitted) = emit_at(scene, targets, pass, n, quasi, guide, &mut rng);
            if let Some(t) = target {
                tally.aimed[t][0] += 1;
            }
            if let Some((ray, departure, power)) = emitted {
                return Some(Path {
                    ray,
                    departure,
                    power,
                    rng,
                    target: target.map_or(NO_TARGET, |t| t as u32),
                    bounce: 0,
                    specular_bounces: 0,
                    only_specular_so_far: true,
                });
            }
        }
        None
    };
    let mut lanes: [Option<Path>; L] = std::array::from_fn(|_| start(&mut next, &mut tally));
    loop {
        let mut alive = false;
        for lane in lanes.iter_mut() {
            let Some(path) = lane else { continue };
            alive = true;
            tally.rays += 1;
            let target = path.target;
            let first = path.bounce == 0;
            let (go_on, first_specular, hit) = step(scene, pass, path, out);
            tally.landed += (first && hit) as u64;
            if first_specular {
                tally.first_specular += 1;
                if let Some(t) = tally.aimed.get_mut(target as usize) {
                    t[1] += 1;
                }
            }
            if !go_on {
                *lane = start(&mut next, &mut tally);
            }
        }
        if !alive {
            return tally;
        }
    }
}

/// Casts one segment of `path`: stores a photon where it lands on a diffuse
/// surface and samples the next direction. Returns whether the path goes
/// on, whether this was the first segment and it hit a specular surface,
/// and whether the segment met anything.
#[inline(always)]
fn step(scene: &Scene, pass: Pass, path: &mut Path, out: &mut Vec<Photon>) -> (bool, bool, bool) {
    let Path { ray, departure, power, rng, bounce, specular_bounces, only_specular_so_far, .. } = path;
    let bounce_now = *bounce;
    *bounce += 1;
    let Some(hit) = scene.intersect(ray, *departure) else {
        return (false, false, false);
    };
    *power *= scene.transmittance(*departure, hit.t);
    let material = &scene.material_seen(&hit, ray.dir);
    let (frame, entering) = hit.scattering_frame(ray.dir, material);
    let first_specular = bounce_now == 0 && material.is_specular();
    let stop = (false, first_specular, true);
    if scene.stores_photons(&hit, material) {
        // Light reaching a diffuse surface straight from the light is
        // neither a caustic nor in the global map: shadow rays count it,
        // at the camera's points and at the irradiance cache's. After a
        // diffuse bounce it is indirect light (final gathering counts it).
        let caustic = *only_specular_so_far && *specular_bounces > 0;
        if (pass == Pass::Global && bounce_now > 0) || caustic {
            out.push(Photon::new(hit.point, *power, frame.n));
        }
    }
    // Russian roulette: survivors carry power / p.
    let wo = frame.to_local(-ray.dir);
    let p = material.photon_survival(wo);
    if p < 1.0 && !(rng.random::<f32>() < p) {
        return stop;
    }
    let Some(scatter) = material.sample(wo, entering, Transport::Importance, rng) else {
        return stop;
    };
    let dir = match scatter.lobe {
        // A cosine sample is unit length, and so, to rounding (a few ulps),
        // is its image in the orthonormal frame: the diffuse bounces, most
        // of the global pass, skip the normalisation, whose square root and
        // division sat on the path from one hit to the next ray (-8% of the
        // pass).
        Lobe::Diffuse => frame.to_world(scatter.wi),
        // Specular directions are normalised: a chain of mirror or glass
        // bounces would carry their rounding from one to the next.
        Lobe::Specular | Lobe::Glossy => frame.to_world(scatter.wi).normalize(),
    };
    let smooth = hit.shading_normal != hit.normal;
    // About a shading normal, a sample may leave on the wrong side of the
    // actual surface: no light goes that way.
    if smooth && !hit.leaves_as(ray.dir, dir, scatter.wi.z > 0.0) {
        return stop;
    }
    // A glossy lobe that carries caustics stands for a specular one
    // (material::Glossy).
    let specular = match scatter.lobe {
        Lobe::Specular => true,
        Lobe::Diffuse => false,
        Lobe::Glossy => material.glossy().is_some_and(|g| g.carries_caustics()),
    };
    match specular {
        true => *specular_bounces += 1,
        // A caustic path ends at its first bounce that is neither.
        false if pass == Pass::Caustic => return stop,
        false => *only_specular_so_far = false,
    }
    *power *= scatter.weight / p;
    if smooth {
        *power *= hit.adjoint_correction(-ray.dir, dir);
    }
    if max_component(*power) <= 0.0 || *bounce >= MAX_BOUNCES {
        return stop;
    }
    let (next, dep) = hit.spawn(dir);
    (*ray, *departure) = (next, Some(dep));
    (true, first_specular, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Eye, Scene};

    /// Photons traced two at a time are the photons traced one after
    /// another (each has its own random stream): the same set, every bit.
    #[test]
    fn lanes_store_the_photons_of_the_plain_loop() {
        let scene = Scene::tncg15(Eye::One);
        for pass in [Pass::Global, Pass::Caustic] {
            let domain = if pass == Pass::Global { Domain::GlobalPhotons } else { Domain::CausticPhotons };
            let targets = specular_targets(&scene);
            let run = |lanes: usize| {
                let mut out = Vec::new();
                let counts = match lanes {
                    1 => trace_range::<1>(
                        &scene,
                        &targets,
                        pass,
                        8000,
                        3,
                        Sequence { seed: 3, first: 0 },
                        None,
                        domain,
                        1000..5000,
                        &mut out,
                    ),
                    _ => trace_range::<LANES>(
                        &scene,
                        &targets,
                        pass,
                        8000,
                        3,
                        Sequence { seed: 3, first: 0 },
                        None,
                        domain,
                        1000..5000,
                        &mut out,
                    ),
                };
                let mut bits: Vec<[u32; 7]> = out
                    .iter()
                    .map(|p| {
                        let [a, b, c] = p.pos.map(f32::to_bits);
                        let [d, e, f] = p.power.map(f32::to_bits);
                        [a, b, c, d, e, f, u32::from_le_bytes(p.normal.map(|x| x as u8))]
                    })
                    .collect();
                bits.sort_unstable();
                (bits, counts)
            };
            let (one, two) = (run(1), run(2));
            assert!(one.0.len() > 1000, "{pass:?}: {} photons", one.0.len());
            assert_eq!(one, two, "{pass:?}");
        }
    }

    #[test]
    fn same_seed_same_photons_on_any_thread_count() {
        let scene = Scene::tncg15(Eye::One);
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| trace_pass(&scene, Pass::Caustic, 20_000, 5, &|_| {}).photons)
        };
        let a = run(1);
        assert!(!a.is_empty());
        assert_eq!(a, run(3));
    }

    /// Regression: a direction drawn at the rim of the chosen aiming cone
    /// could fail the containment test by rounding, leaving a zero pdf and an
    /// infinite photon power (seed 5 at 2e5 photons hit it 123 times).
    #[test]
    fn caustic_photons_at_the_rim_of_the_aiming_cone_have_finite_power() {
        let scene = Scene::tncg15(Eye::One);
        let out = trace_pass(&scene, Pass::Caustic, 200_000, 5, &|_| {});
        assert!(out.photons.len() > 150_000);
        assert!(out.photons.iter().all(|p| p.flux().is_finite() && p.flux().max_element() > 0.0));
    }

    /// Regression: with every light at radiance 0 the light was chosen with
    /// probability 0 / 0 and every photon carried NaN power.
    #[test]
    fn a_light_of_radiance_zero_emits_no_photons() {
        let mut parts = Scene::tncg15_parts(Eye::One);
        let crate::light::Light::Area(a) = &mut parts.lights[0] else { panic!() };
        a.radiance = crate::math::Color::ZERO;
        let scene = Scene::from_parts(parts);
        for pass in [Pass::Global, Pass::Caustic] {
            let out = trace_pass(&scene, pass, 1000, 1, &|_| {});
            assert!(out.photons.is_empty());
            assert_eq!(out.emitted, 1000);
        }
    }

    #[test]
    fn global_photons_carry_power_over_n_and_roulette_keeps_energy() {
        // First-hit photons of the global pass carry exactly Phi / N each, and
        // the mean stored power per emitted photon matches Phi * sum of the
        // expected reflected fractions: at least the first hits' Phi.
        let scene = Scene::tncg15(Eye::One);
        let n = 50_000;
        let out = trace_pass(&scene, Pass::Global, n, 3, &|_| {});
        let phi = scene.emitted_power().x;
        let first = phi / n as f32;
        assert!(out.photons.iter().any(|p| (p.power[0] - first).abs() < 1e-6 * first));
        let total: f64 = out.photons.iter().map(|p| p.power[0] as f64).sum();
        // Every emitted photon lands somewhere first (closed room): total > 0.9 Phi.
        assert!(total > 0.9 * phi as f64, "{total}");
    }
}
