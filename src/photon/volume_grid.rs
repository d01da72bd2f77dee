//! The global volume photons as a grid of in-scattered light: each
//! medium's photons splatted once per pass into the vertices of a grid
//! over their bounding box (a tent kernel: a photon's power shared among
//! the 8 vertices of its cell by trilinear weights), read along a camera
//! segment cell by cell (the trilinear interpolant of the vertices, a
//! cubic along the segment within a cell, integrated with the
//! transmittance by two-point Gauss–Legendre). A segment's cost is the
//! cells it crosses, not the photons it passes: the beam estimate
//! ([`super::volume_map`]) reads every photon whose sphere the segment
//! crosses, and that grows with the photons stored.
//!
//! Each vertex keeps the power (RGB) and the luminance-weighted sum of the
//! photons' directions; the light's angular distribution at a point is
//! kept as its mean direction m (|m| ≤ 1, the first Legendre moment) and
//! taken to be a Henyey–Greenstein lobe about m of mean cosine |m|. A
//! Henyey–Greenstein phase function of asymmetry g multiplies the l-th
//! Legendre coefficient of the light by g^l, so the light scattered
//! towards the eye is then HG(g |m|) about m: exact in the first two
//! moments (any distribution), exact altogether where the light's
//! distribution is itself such a lobe (light scattered once from a
//! collimated beam in the medium), never negative (a truncated Legendre
//! series is, at |3 g cos| > 1). An isotropic medium needs no direction.
//!
//! The grid's box is the photons' bounding box with vertices on its faces;
//! a vertex's power is divided by the volume of its tent inside the box,
//! so a medium that fills a box (a room of fog, a grid's box of smoke)
//! reads its density without loss at the walls. Its spacing is set by the
//! photons' density, so the estimate converges as photons grow (see
//! [`VolumeGrid::build`]).

use super::volume_map::VolumePhoton;
use crate::math::{Color, Ray};
use crate::medium::{Aabb, Phase};
use glam::Vec3;
use std::collections::HashSet;

/// The most vertices of one medium's grid (24 bytes each: 100 MB); a
/// denser grid's spacing grows to fit.
const MAX_VERTICES: f32 = (1u32 << 22) as f32;

/// The cell's side over the radius of the sphere that holds k photons at
/// their mean density: the blur of the tent splat and trilinear read
/// together (a per-axis variance of h²/3) equals the beam estimate's disk
/// of that radius (r²/4) at √3/2.
const SPACING: f32 = 0.866;

/// Gauss–Legendre's two nodes on [0, 1].
const GL: [f32; 2] = [0.5 - 0.288_675_13, 0.5 + 0.288_675_13];

#[derive(Clone, Debug)]
struct MediumGrid {
    lo: Vec3,
    /// Cell sides.
    h: Vec3,
    /// Cells per axis (vertices one more).
    n: [u32; 3],
    /// Per vertex: power per unit volume (RGB), then the sum of the
    /// photons' directions weighted by their power's luminance, per unit
    /// volume.
    v: Vec<[f32; 6]>,
}

/// The global volume photons of a pass as grids, one per medium.
#[derive(Debug, Default)]
pub struct VolumeGrid {
    grids: Vec<Option<MediumGrid>>,
    photons: usize,
}

fn luminance(c: Color) -> f32 {
    crate::texture::luminance(c)
}

impl VolumeGrid {
    /// The grids of `photons`: per medium, cells of side [`SPACING`] times
    /// the radius of the sphere holding `k` photons at their mean density
    /// over the space they occupy (counted in cells of about `k` photons
    /// were they spread evenly through their box), at most `r_max`, times
    /// `shrink` (a progressive pass's narrowing; 1 in a classic render).
    pub fn build(photons: &[VolumePhoton], k: usize, r_max: f32, shrink: f32) -> Self {
        let media = photons.iter().map(|p| p.medium as usize + 1).max().unwrap_or(0);
        let mut grids = Vec::with_capacity(media);
        for m in 0..media as u32 {
            let mine: Vec<&VolumePhoton> = photons.iter().filter(|p| p.medium == m).collect();
            grids.push(MediumGrid::build(&mine, k, r_max, shrink));
        }
        VolumeGrid { grids, photons: photons.len() }
    }

    pub fn len(&self) -> usize {
        self.photons
    }

    pub fn is_empty(&self) -> bool {
        self.photons == 0
    }

    pub fn memory_bytes(&self) -> usize {
        self.grids.iter().flatten().map(|g| g.v.len() * std::mem::size_of::<[f32; 6]>()).sum()
    }

    /// The light medium `m` (of phase function `phase`) scatters towards
    /// the eye along `ray` over [0, `t_max`], each distance weighed by
    /// `tr`, the transmittance from the ray's origin to it.
    pub fn integrate(&self, m: u32, phase: &Phase, ray: &Ray, t_max: f32, tr: impl FnMut(f32) -> Color) -> Color {
        match self.grids.get(m as usize) {
            Some(Some(g)) => g.integrate(phase.mean_cosine(), ray, t_max, tr),
            _ => Color::ZERO,
        }
    }
}

impl MediumGrid {
    fn build(photons: &[&VolumePhoton], k: usize, r_max: f32, shrink: f32) -> Option<Self> {
        if photons.is_empty() {
            return None;
        }
        let (lo, hi) = photons
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(a, b), p| (a.min(p.pos), b.max(p.pos)));
        let extent = (hi - lo).max(Vec3::splat(1e-4 * (hi - lo).max_element().max(1e-4)));
        // The space the photons occupy: the coarse cells holding any.
        let coarse = (extent.x * extent.y * extent.z * k as f32 / photons.len() as f32).cbrt().max(1e-6);
        let mut occupied: HashSet<(i32, i32, i32)> = HashSet::with_capacity(photons.len() / k.max(1) + 1);
        for p in photons {
            let c = ((p.pos - lo) / coarse).floor();
            occupied.insert((c.x as i32, c.y as i32, c.z as i32));
        }
        let volume = (occupied.len() as f32 * coarse.powi(3)).min(extent.x * extent.y * extent.z).max(1e-12);
        let density = photons.len() as f32 / volume;
        let r = (3.0 * k as f32 / (4.0 * std::f32::consts::PI * density)).cbrt();
        let mut side = SPACING * if r.is_finite() { r.min(r_max) } else { r_max } * shrink;
        let cells = |side: f32| (extent / side).ceil().max(Vec3::ONE);
        let vertices = |c: Vec3| (c.x + 1.0) * (c.y + 1.0) * (c.z + 1.0);
        while vertices(cells(side)) > MAX_VERTICES {
            side *= 1.25;
        }
        let c = cells(side);
        let n = [c.x as u32, c.y as u32, c.z as u32];
        let h = extent / c;
        let (nx, ny) = (n[0] as usize + 1, n[1] as usize + 1);
        let mut v = vec![[0.0f32; 6]; nx * ny * (n[2] as usize + 1)];
        // In the photons' order, one after another: the same sums on any
        // thread count.
        for p in photons {
            let u = ((p.pos - lo) / h).clamp(Vec3::ZERO, c);
            let cell = u.floor().min(c - Vec3::ONE);
            let f = u - cell;
            let (i, j, l) = (cell.x as usize, cell.y as usize, cell.z as usize);
            let dir = p.direction() * luminance(p.power);
            for corner in 0..8 {
                let (a, b, e) = (corner & 1, (corner >> 1) & 1, corner >> 2);
                let w = (if a == 1 { f.x } else { 1.0 - f.x })
                    * (if b == 1 { f.y } else { 1.0 - f.y })
                    * (if e == 1 { f.z } else { 1.0 - f.z });
                let slot = &mut v[((l + e) * ny + j + b) * nx + i + a];
                let add = [p.power.x, p.power.y, p.power.z, dir.x, dir.y, dir.z];
                for (s, a) in slot.iter_mut().zip(add) {
                    *s += w * a;
                }
            }
        }
        // Each vertex over its tent's volume inside the box: half a cell's
        // span on each axis where it lies on a face.
        let cell_volume = h.x * h.y * h.z;
        for zi in 0..=n[2] as usize {
            for yi in 0..ny {
                for xi in 0..nx {
                    let half = |i: usize, last: usize| if i == 0 || i == last { 0.5 } else { 1.0 };
                    let inside = cell_volume * half(xi, nx - 1) * half(yi, ny - 1) * half(zi, n[2] as usize);
                    for s in &mut v[(zi * ny + yi) * nx + xi] {
                        *s /= inside;
                    }
                }
            }
        }
        Some(MediumGrid { lo, h, n, v })
    }

    /// The vertices' values interpolated at `f` (in [0, 1]³) within the
    /// cell at `base` (the index of its lowest vertex).
    #[inline]
    fn read(&self, base: usize, f: Vec3) -> [f32; 6] {
        let nx = self.n[0] as usize + 1;
        let ny = self.n[1] as usize + 1;
        let mut out = [0.0f32; 6];
        for corner in 0..8 {
            let (a, b, e) = (corner & 1, (corner >> 1) & 1, corner >> 2);
            let w = (if a == 1 { f.x } else { 1.0 - f.x })
                * (if b == 1 { f.y } else { 1.0 - f.y })
                * (if e == 1 { f.z } else { 1.0 - f.z });
            let s = &self.v[base + (e * ny + b) * nx + a];
            for (o, x) in out.iter_mut().zip(s) {
                *o += w * x;
            }
        }
        out
    }

    fn integrate(&self, g: f32, ray: &Ray, t_max: f32, mut tr: impl FnMut(f32) -> Color) -> Color {
        let cells = Vec3::new(self.n[0] as f32, self.n[1] as f32, self.n[2] as f32);
        let hi = self.lo + self.h * cells;
        let Some((t0, t1)) = (Aabb { lo: self.lo, hi }).clip(ray, t_max) else { return Color::ZERO };
        if !(t1 > t0) {
            return Color::ZERO;
        }
        let out = -ray.dir;
        let (nx, ny) = (self.n[0] as usize + 1, self.n[1] as usize + 1);
        // Amanatides and Woo's walk through the cells between vertex planes.
        let start = ((ray.at(t0) - self.lo) / self.h).clamp(Vec3::ZERO, cells - Vec3::splat(1e-3));
        let mut cell = [0i64; 3];
        let mut step = [0i64; 3];
        let mut t_next = [f32::INFINITY; 3];
        let mut t_delta = [f32::INFINITY; 3];
        for a in 0..3 {
            let c = start[a].floor().min(cells[a] - 1.0).max(0.0);
            cell[a] = c as i64;
            let d = ray.dir[a];
            if d > 0.0 {
                step[a] = 1;
                t_delta[a] = self.h[a] / d;
                t_next[a] = t0 + (c + 1.0 - start[a]) * t_delta[a];
            } else if d < 0.0 {
                step[a] = -1;
                t_delta[a] = -self.h[a] / d;
                t_next[a] = t0 + (start[a] - c) * t_delta[a];
            }
        }
        let mut sum = Color::ZERO;
        let mut t = t0;
        while t < t1 {
            let axis = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            let end = t_next[axis].min(t1);
            if end > t {
                let base = (cell[2] as usize * ny + cell[1] as usize) * nx + cell[0] as usize;
                let corner = self.lo + self.h * Vec3::new(cell[0] as f32, cell[1] as f32, cell[2] as f32);
                let len = end - t;
                for node in GL {
                    let s = t + node * len;
                    let f = ((ray.at(s) - corner) / self.h).clamp(Vec3::ZERO, Vec3::ONE);
                    let x = self.read(base, f);
                    let power = Color::new(x[0], x[1], x[2]);
                    let lum = luminance(power);
                    if !(lum > 0.0) {
                        continue;
                    }
                    let phase = if g == 0.0 {
                        1.0 / (4.0 * std::f32::consts::PI)
                    } else {
                        let mean = Vec3::new(x[3], x[4], x[5]) / lum;
                        let len_m = mean.length().min(1.0);
                        if len_m > 1e-6 {
                            Phase::HenyeyGreenstein { g: g * len_m }.eval(mean / mean.length(), out)
                        } else {
                            1.0 / (4.0 * std::f32::consts::PI)
                        }
                    };
                    sum += power * tr(s) * (0.5 * len * phase);
                }
            }
            if t_next[axis] >= t1 {
                break;
            }
            t = end;
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= self.n[axis] as i64 {
                break;
            }
            t_next[axis] += t_delta[axis];
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::volume_map::VolumeMap;
    use crate::sampling::{stream, Domain};
    use rand::RngExt;

    fn uniform(n: usize, seed: u64, dir: impl Fn(&mut crate::sampling::Rng) -> Vec3) -> Vec<VolumePhoton> {
        let mut rng = stream(seed, Domain::Camera, 3);
        (0..n)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random());
                let d = dir(&mut rng);
                VolumePhoton::new(p, Color::splat(1.0 / n as f32), d, 0)
            })
            .collect()
    }

    /// With photons of total power Φ spread uniformly through a unit cube,
    /// isotropic, a segment of length L reads Φ L / (4π) on average,
    /// including segments that end on the cube's faces (the vertices on a
    /// face are divided by the half of their tent inside) and ones that
    /// start outside it.
    #[test]
    fn a_uniform_density_reads_its_integral_up_to_the_walls() {
        let photons = uniform(200_000, 5, |_| Vec3::Z);
        let grid = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let mut rng = stream(6, Domain::Camera, 4);
        let iso = Phase::Isotropic;
        for (origin, dir, len, expect) in [
            (0.0f32, Vec3::X, 1.0f32, 1.0f32),
            (0.97, Vec3::X, 0.03, 0.03),
            (0.03, -Vec3::X, 0.03, 0.03),
            (-1.0, Vec3::X, 1.2, 0.2),
        ] {
            let rays = 2000;
            let mut sum = 0.0f64;
            for _ in 0..rays {
                let (y, z) = (rng.random::<f32>(), rng.random::<f32>());
                let ray = Ray::new(Vec3::new(origin, y, z), dir);
                sum += grid.integrate(0, &iso, &ray, len, |_| Color::ONE).x as f64;
            }
            let mean = sum / rays as f64 * 4.0 * std::f64::consts::PI;
            assert!((mean / expect as f64 - 1.0).abs() < 0.03, "from {origin} along {dir}: {mean} against {expect}");
        }
    }

    /// The grid and the beam estimate agree on the same photons, weighed by
    /// a transmittance and a Henyey–Greenstein phase function, where the
    /// photons' directions are themselves a Henyey–Greenstein lobe about
    /// one axis (which the grid's moment keeps exactly): mean over many
    /// segments within 2%, and the grid reads a forward-scattered lobe
    /// brighter than a backward one as the beam does.
    #[test]
    fn the_grid_agrees_with_the_beam_estimate() {
        let g_light = 0.5;
        let lobe = Phase::HenyeyGreenstein { g: g_light };
        let photons = uniform(300_000, 8, |rng| lobe.sample(Vec3::X, glam::Vec2::new(rng.random(), rng.random())).0);
        let grid = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let map = VolumeMap::build(photons, 24, 0.2, 1.0);
        let phase = Phase::HenyeyGreenstein { g: 0.6 };
        let sigma = 0.8f32;
        let mut rng = stream(10, Domain::Camera, 5);
        for dir in [Vec3::X, -Vec3::X, Vec3::Y] {
            let (mut a, mut b) = (0.0f64, 0.0f64);
            for _ in 0..1500 {
                let (u, v) = (0.1 + 0.8 * rng.random::<f32>(), 0.1 + 0.8 * rng.random::<f32>());
                let o = if dir == Vec3::Y {
                    Vec3::new(u, 0.0, v)
                } else if dir == Vec3::X {
                    Vec3::new(0.0, u, v)
                } else {
                    Vec3::new(1.0, u, v)
                };
                let ray = Ray::new(o, dir);
                a += grid.integrate(0, &phase, &ray, 1.0, |t| Color::splat((-sigma * t).exp())).x as f64;
                map.beam(&ray, 1.0, |c| {
                    b += (c.photon.power.x * c.kernel * phase.eval(c.photon.direction(), -dir) * (-sigma * c.t).exp())
                        as f64
                });
            }
            println!("{dir}: grid {a} beam {b}");
            assert!((a / b - 1.0).abs() < 0.02, "{dir}: grid {a} beam {b}");
        }
    }

    /// A medium's grid holds only the photons that scattered in it: a
    /// medium without photons (or past the last) reads nothing.
    #[test]
    fn media_are_kept_apart() {
        let mut photons = uniform(10_000, 12, |_| Vec3::Z);
        for p in photons.iter_mut().step_by(2) {
            p.medium = 2;
        }
        let grid = VolumeGrid::build(&photons, 24, 0.2, 1.0);
        let ray = Ray::new(Vec3::new(0.0, 0.5, 0.5), Vec3::X);
        let iso = Phase::Isotropic;
        let (a, b, c) = (
            grid.integrate(0, &iso, &ray, 1.0, |_| Color::ONE),
            grid.integrate(1, &iso, &ray, 1.0, |_| Color::ONE),
            grid.integrate(2, &iso, &ray, 1.0, |_| Color::ONE),
        );
        assert_eq!(b, Color::ZERO);
        assert!(a.x > 0.0 && c.x > 0.0);
        assert!(grid.integrate(3, &iso, &ray, 1.0, |_| Color::ONE) == Color::ZERO);
    }
}
