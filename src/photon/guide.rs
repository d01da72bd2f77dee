//! Where the global pass sends the photons of light at infinity (a
//! directional light, a sky, an environment map): their starts cover a
//! disk or box shadow around the whole scene, and in a closed room lit
//! through a window nearly all of them land on the room's outside. A
//! pilot finds which cells of the light's own sample space lead to light
//! the camera sees, and the pass draws cells in proportion to that, mixed
//! with a uniform part (defensive importance sampling, Hesterberg 1995):
//! every cell keeps a density of at least [`UNIFORM`] times its natural
//! one, and each photon's power is divided by its exact density relative
//! to the light's natural sampling, so the maps' expectation is unchanged.
//!
//! The cells are those of the uniform numbers the light turns into a start
//! ([`crate::light::Source::sample_le`]): the start's square (a
//! directional light's disk by the concentric map; a sky's or an
//! environment map's position on the scene box's shadow) and, for a light
//! from everywhere, its direction's square. A cell of the natural sampling
//! holds 1 / C of the photons; the guide gives it `p_c`, and its photons
//! carry `1 / (C p_c)` times their power.
//!
//! What the camera sees is a coarse grid over the scene's box: the cells
//! where a camera ray (through mirrors and glass) first meets a diffuse or
//! glossy surface, by the side of the surface it faces (a wall of no
//! thickness is seen from inside the room only: photons on its outside
//! face do not count), and, in a scene with media, every cell the camera
//! ray crosses. A pilot photon is useful where its first hit, or any
//! photon it stores, lies in a seen cell on a seen side. The pilot's
//! random streams are keyed by (seed, index), so the guide, and the
//! photons, are the same on any number of threads.

use crate::light::Light;
use crate::math::{max_component, Color, Ray};
use crate::sampling::{next_2d, stream, Discrete, Domain, Rng};
use crate::scene::Scene;
use crate::shape::Departure;
use glam::{Vec2, Vec3};
use rand::RngExt;
use rayon::prelude::*;

/// The share of every guided pass drawn uniformly over the cells: a cell
/// the pilot found useless still gets this share of its natural density,
/// so no photon carries more than 1 / UNIFORM times its natural power.
pub const UNIFORM: f64 = 0.2;
/// Cells per side of the start's square of a light of one direction.
const PARALLEL_SIDE: u32 = 128;
/// Cells per side of the start's and the direction's squares of light
/// from everywhere.
const POSITION_SIDE: u32 = 16;
const DIRECTION_SIDE: u32 = 8;
/// Pilot photons per cell.
const PILOT_PER_CELL: u64 = 4;
/// Cells per side of the grid of seen places over the scene's box.
const SEEN_SIDE: u32 = 32;
/// Camera rays per side of the image in the pilot of seen places.
const CAMERA_SIDE: u32 = 64;
/// Mirror and glass bounces a camera ray of the pilot follows.
const CAMERA_BOUNCES: u32 = 8;

/// Cells of the scene's box the camera sees, by the side seen.
#[derive(Clone, Debug)]
pub struct Seen {
    lo: Vec3,
    /// Cells per unit length.
    scale: f32,
    /// One bit per (cell, class): classes 0-5 a surface facing +x, -x, +y,
    /// -y, +z, -z; class 6 the cell's volume.
    bits: Vec<u64>,
}

const CLASSES: usize = 7;
const VOLUME: usize = 6;

/// The class of a surface whose normal, turned towards the viewer or the
/// arriving photon, is `n`: its dominant axis and sign, as the photon
/// maps' trees split them.
fn surface_class(n: Vec3) -> usize {
    super::facing::class_of(n)
}

impl Seen {
    fn new(scene: &Scene) -> Self {
        let (lo, hi) = scene.bounds();
        let extent = (hi - lo).max_element().max(1e-6);
        let scale = SEEN_SIDE as f32 / extent;
        let cells = (SEEN_SIDE as usize).pow(3) * CLASSES;
        Seen { lo, scale, bits: vec![0; cells.div_ceil(64)] }
    }

    fn cell(&self, p: Vec3) -> Option<[i32; 3]> {
        let c = ((p - self.lo) * self.scale).floor();
        let s = SEEN_SIDE as f32;
        (c.cmpge(Vec3::splat(-1.0)).all() && c.cmple(Vec3::splat(s)).all())
            .then(|| [c.x as i32, c.y as i32, c.z as i32].map(|v| v.clamp(0, SEEN_SIDE as i32 - 1)))
    }

    fn index(c: [i32; 3], class: usize) -> usize {
        let s = SEEN_SIDE as usize;
        ((c[2] as usize * s + c[1] as usize) * s + c[0] as usize) * CLASSES + class
    }

    fn mark(&mut self, p: Vec3, class: usize) {
        if let Some(c) = self.cell(p) {
            let i = Self::index(c, class);
            self.bits[i / 64] |= 1 << (i % 64);
        }
    }

    fn holds(&self, p: Vec3, class: usize) -> bool {
        self.cell(p).is_some_and(|c| {
            let i = Self::index(c, class);
            self.bits[i / 64] & (1 << (i % 64)) != 0
        })
    }

    /// Whether a surface point facing `n` (towards where light arrives
    /// from) is seen.
    pub fn surface(&self, p: Vec3, n: Vec3) -> bool {
        self.holds(p, surface_class(n))
    }

    /// Whether a point in a medium is seen.
    pub fn volume(&self, p: Vec3) -> bool {
        self.holds(p, VOLUME)
    }

    /// Every marked cell's neighbours marked too, in the same class: the
    /// camera's pilot rays are sparser than the cells far from it.
    fn dilated(&self) -> Self {
        let mut out = self.clone();
        let s = SEEN_SIDE as i32;
        for z in 0..s {
            for y in 0..s {
                for x in 0..s {
                    for class in 0..CLASSES {
                        let i = Self::index([x, y, z], class);
                        if self.bits[i / 64] & (1 << (i % 64)) == 0 {
                            continue;
                        }
                        for (dx, dy, dz) in neighbours() {
                            let c = [x + dx, y + dy, z + dz];
                            if c.iter().all(|&v| (0..s).contains(&v)) {
                                let j = Self::index(c, class);
                                out.bits[j / 64] |= 1 << (j % 64);
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// The places the camera of `scene` sees: camera rays through a grid
    /// of the image, through mirrors and glass (the first of their
    /// branches a random choice picks), to the first other surface; with
    /// `volumes`, every cell along the way too.
    pub fn by_camera(scene: &Scene, volumes: bool, seed: u64) -> Self {
        let mut seen = Seen::new(scene);
        let camera = &scene.camera;
        let step = 0.5 / seen.scale;
        let reach = 2.0 * scene.diagonal();
        for j in 0..CAMERA_SIDE {
            for i in 0..CAMERA_SIDE {
                let x = (i as f32 + 0.5) / CAMERA_SIDE as f32 * camera.width as f32;
                let y = (j as f32 + 0.5) / CAMERA_SIDE as f32 * camera.height as f32;
                let (col, row) = (x as u32, y as u32);
                let mut ray = camera.ray(col, row, Vec2::new(x - col as f32, y - row as f32));
                let mut departure: Option<Departure> = None;
                let mut rng = stream(seed, Domain::EmissionPilot, u64::MAX - (j * CAMERA_SIDE + i) as u64);
                for _ in 0..CAMERA_BOUNCES {
                    let hit = scene.intersect(&ray, departure);
                    if volumes {
                        let end = hit.as_ref().map_or(reach, |h| h.t.min(reach));
                        let mut t = 0.5 * step;
                        while t < end {
                            seen.mark(ray.at(t), VOLUME);
                            t += step;
                        }
                    }
                    let Some(hit) = hit else { break };
                    let material = scene.material_seen(&hit, ray.dir);
                    if !material.is_specular() {
                        seen.mark(hit.point, surface_class(hit.facing_normal(ray.dir)));
                        break;
                    }
                    let (frame, entering) = hit.scattering_frame(ray.dir, &material);
                    let wo = frame.to_local(-ray.dir);
                    let mode = crate::material::Transport::Radiance;
                    let Some(s) = material.sample(wo, entering, mode, &mut rng) else { break };
                    let (next, dep) = hit.spawn(frame.to_world(s.wi).normalize());
                    (ray, departure) = (next, Some(dep));
                }
            }
        }
        seen.dilated()
    }
}

/// The 26 neighbours of a cell and the cell itself.
fn neighbours() -> impl Iterator<Item = (i32, i32, i32)> {
    (-1..=1).flat_map(|z| (-1..=1).flat_map(move |y| (-1..=1).map(move |x| (x, y, z))))
}

/// Where a pilot photon's light went: what the photon pass stored of it,
/// each at a surface facing its normal (towards where the photon came
/// from) or in a medium (`None`).
pub type Stored = Vec<(Vec3, Option<Vec3>)>;

/// The pass's tracing of one pilot photon (its start, departure, power
/// and random stream): where it stored photons.
pub type PilotTrace<'a> = dyn Fn(Ray, Option<Departure>, Color, &mut Rng) -> Stored + Sync + 'a;

/// One light's guide: the cells of its sample space and their chances.
#[derive(Clone, Debug)]
struct LightGuide {
    /// Cells per side of the start's square and of the direction's.
    position_side: u32,
    direction_side: u32,
    cells: Discrete,
    /// The share of the light's photons the pilot found useful, under the
    /// light's natural sampling and under the guide.
    natural: f64,
    guided: f64,
}

impl LightGuide {
    fn count(&self) -> u32 {
        (self.position_side * self.direction_side).pow(2)
    }

    /// The uniform numbers of cell `c`'s point `r` (two in [0, 1)²).
    fn point(&self, c: usize, r: [Vec2; 2]) -> (Vec2, Vec2) {
        let d2 = (self.direction_side * self.direction_side) as usize;
        let (pos, dir) = (c / d2, c % d2);
        let at = |cell: usize, side: u32, r: Vec2| {
            let (x, y) = ((cell % side as usize) as f32, (cell / side as usize) as f32);
            ((Vec2::new(x, y) + r) / side as f32).min(Vec2::splat(1.0 - f32::EPSILON / 2.0))
        };
        (at(pos, self.position_side, r[0]), at(dir, self.direction_side, r[1]))
    }

    /// Each cell's score the largest of its own and its neighbours' in the
    /// start's square (the same direction's cell).
    fn spread(&self, scores: &[f64]) -> Vec<f64> {
        let (p, d2) = (self.position_side as i64, (self.direction_side * self.direction_side) as usize);
        (0..scores.len())
            .map(|c| {
                let (pos, dir) = ((c / d2) as i64, c % d2);
                let (x, y) = (pos % p, pos / p);
                let mut best = 0.0f64;
                for (dx, dy, _) in neighbours().filter(|n| n.2 == 0) {
                    let (i, j) = (x + dx as i64, y + dy as i64);
                    if (0..p).contains(&i) && (0..p).contains(&j) {
                        best = best.max(scores[(j * p + i) as usize * d2 + dir]);
                    }
                }
                best
            })
            .collect()
    }

    /// The cell of the uniform numbers (`u_pos`, `u_dir`).
    fn cell_of(&self, u_pos: Vec2, u_dir: Vec2) -> usize {
        let idx = |u: Vec2, side: u32| {
            let c = (u * side as f32).floor().clamp(Vec2::ZERO, Vec2::splat(side as f32 - 1.0));
            c.y as usize * side as usize + c.x as usize
        };
        let d2 = (self.direction_side * self.direction_side) as usize;
        idx(u_pos, self.position_side) * d2 + idx(u_dir, self.direction_side)
    }
}

/// The global pass's guide: per light, where its photons are sent.
#[derive(Clone, Debug, Default)]
pub struct EmissionGuide {
    lights: Vec<Option<LightGuide>>,
}

/// Whether `light` is one the guide serves: light at infinity.
fn guided(light: &Light) -> bool {
    light.bounds().is_none() && max_component(light.power()) > 0.0
}

impl EmissionGuide {
    /// The guide of the global pass of `seed` in `scene`, built by a pilot
    /// of photons followed by `trace` (the pass's own tracing, storing what
    /// it would); `None` where the scene has no light at infinity (it pays
    /// nothing) or the pilot found nothing of theirs useful.
    pub fn build(scene: &Scene, volumes: bool, seed: u64, trace: &PilotTrace) -> Option<Self> {
        if !scene.lights.iter().any(guided) {
            return None;
        }
        let seen = Seen::by_camera(scene, volumes, seed);
        let mut first = 0u64;
        let lights: Vec<Option<LightGuide>> = scene
            .lights
            .iter()
            .map(|light| {
                if !guided(light) {
                    return None;
                }
                let direction_side = if light.is_delta() { 1 } else { DIRECTION_SIDE };
                let position_side = if light.is_delta() { PARALLEL_SIDE } else { POSITION_SIDE };
                let shape = LightGuide {
                    position_side,
                    direction_side,
                    cells: Discrete::new([1.0])?,
                    natural: 0.0,
                    guided: 0.0,
                };
                let count = shape.count() as u64;
                let base = first;
                first += count * PILOT_PER_CELL;
                // Per cell, the pilot's useful photons' weight (the light's
                // own weight of each start: one on average).
                let scores: Vec<f64> = (0..count)
                    .into_par_iter()
                    .map(|c| {
                        (0..PILOT_PER_CELL)
                            .map(|j| {
                                let mut rng = stream(seed, Domain::EmissionPilot, base + c * PILOT_PER_CELL + j);
                                let (u_pos, u_dir) = shape.point(c as usize, [next_2d(&mut rng), next_2d(&mut rng)]);
                                let e = light.sample_le(u_pos, u_dir);
                                let w = max_component(e.weight) as f64;
                                if !(w > 0.0) {
                                    return 0.0;
                                }
                                let useful = lands_seen(scene, &seen, &e.ray, e.departure)
                                    || trace(e.ray, e.departure, light.power() * e.weight, &mut rng)
                                        .iter()
                                        .any(|&(p, n)| n.map_or_else(|| seen.volume(p), |n| seen.surface(p, n)));
                                if useful {
                                    w
                                } else {
                                    0.0
                                }
                            })
                            .sum::<f64>()
                            / PILOT_PER_CELL as f64
                    })
                    .collect();
                // A cell the pilot found useful lends its score to its
                // neighbours: cells cut by a window's rim, which few pilot
                // photons found, would else carry photons of many times
                // the power of their neighbours' (speckles).
                let scores = shape.spread(&scores);
                let total: f64 = scores.iter().sum();
                if !(total > 0.0) {
                    return None;
                }
                let n = count as f64;
                let chances: Vec<f64> = scores.iter().map(|s| UNIFORM / n + (1.0 - UNIFORM) * s / total).collect();
                let cells = Discrete::new(chances.iter().copied())?;
                let natural = total / n;
                let guided = scores.iter().zip(&chances).map(|(s, p)| s * p).sum::<f64>();
                Some(LightGuide { cells, natural, guided, ..shape })
            })
            .collect();
        lights.iter().any(Option::is_some).then_some(EmissionGuide { lights })
    }

    /// The uniform numbers of a start of light `light` drawn by the guide
    /// (its position's and its direction's), and what its power is
    /// multiplied by: the light's natural density over the guide's. `None`
    /// where the guide does not serve the light.
    #[inline]
    pub fn sample(&self, light: usize, rng: &mut Rng) -> Option<(Vec2, Vec2, f32)> {
        let g = self.lights.get(light)?.as_ref()?;
        let (c, _) = g.cells.sample(rng.random::<f32>());
        let (u_pos, u_dir) = g.point(c, [next_2d(rng), next_2d(rng)]);
        Some((u_pos, u_dir, 1.0 / (g.count() as f32 * g.cells.prob(c))))
    }

    /// The density (relative to the light's natural sampling, one on
    /// average) with which [`Self::sample`] draws the uniform numbers
    /// (`u_pos`, `u_dir`) of light `light`; one where it does not serve it.
    pub fn density(&self, light: usize, u_pos: Vec2, u_dir: Vec2) -> f32 {
        match self.lights.get(light).and_then(Option::as_ref) {
            Some(g) => g.count() as f32 * g.cells.prob(g.cell_of(u_pos, u_dir)),
            None => 1.0,
        }
    }

    /// The share of all photons (lights picked by power, `pick`) the pilot
    /// found useful, under natural and under guided emission; lights the
    /// guide does not serve count as useful.
    pub fn useful_shares(&self, pick: impl Fn(usize) -> f32) -> (f64, f64) {
        let mut shares = (0.0, 0.0);
        for (i, g) in self.lights.iter().enumerate() {
            let p = pick(i) as f64;
            let (a, b) = g.as_ref().map_or((1.0, 1.0), |g| (g.natural, g.guided));
            shares.0 += p * a;
            shares.1 += p * b;
        }
        shares
    }
}

/// Whether a photon starting along `ray` first meets, through nothing but
/// media and index-matched surfaces' kin (it stops at the first surface),
/// a surface the camera sees from the side it arrives at.
fn lands_seen(scene: &Scene, seen: &Seen, ray: &Ray, departure: Option<Departure>) -> bool {
    scene.intersect(ray, departure).is_some_and(|h| seen.surface(h.point, h.facing_normal(ray.dir)))
}
