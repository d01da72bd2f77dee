//! The volume photon map: photons stored where they scattered in a
//! participating medium, each with the direction it travelled and the
//! medium it was in, read along camera rays by the beam radiance estimate
//! of Jarosz, Zwicker and Jensen (2008, "The Beam Radiance Estimate for
//! Volumetric Photon Mapping"): every photon is a sphere of its own
//! radius (the distance to its k-th nearest neighbour, capped), and a ray
//! collects every photon whose sphere it crosses, with the 2D kernel
//! 1 / (π r²) about the ray. The spheres are held in a bounding volume
//! hierarchy (median splits, leaves of up to `LEAF` photons).

use crate::math::{Color, Ray};
use crate::medium::Aabb;
use glam::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;

/// One photon that scattered in a medium: 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumePhoton {
    pub pos: Vec3,
    /// Flux carried after the collision's weight (transmittance × σ_s
    /// over the density of the flight): the photons' density is the
    /// source term σ_s ∫ L, which the phase function turns into radiance.
    pub power: Color,
    /// The direction the photon travelled when it scattered, as
    /// [`crate::math::encode_unit`] packs it.
    pub dir: u32,
    /// The medium it scattered in.
    pub medium: u32,
}

impl VolumePhoton {
    pub fn new(pos: Vec3, power: Color, dir: Vec3, medium: u32) -> Self {
        VolumePhoton { pos, power, dir: crate::math::encode_unit(dir), medium }
    }

    pub fn direction(&self) -> Vec3 {
        crate::math::decode_unit(self.dir)
    }
}

/// Grids finer than the first, each half the cell of the one before:
/// where the photons crowd (a volume caustic's cone, a few tenths of a
/// metre across in a room), the first grid's 27 cells span more than the
/// crowd, read a fraction of its density and give its photons spheres
/// several times too wide, which blurs the crowd's light out of it (a
/// bias that shrinks only as the radius does).
const FINER_GRIDS: usize = 4;

/// The squared radius of each photon of `photons` (see [`VolumeMap::build`]).
fn radii(photons: &[VolumePhoton], k: usize, r_max: f32, shrink: f32) -> Vec<f32> {
    let (lo, hi) =
        photons.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(a, b), p| (a.min(p.pos), b.max(p.pos)));
    let extent = (hi - lo).max(Vec3::splat(1e-6 * (hi - lo).max_element().max(1e-6)));
    // Cells of about k photons were the photons spread evenly through
    // their box; no smaller than a tenth of the cap.
    let coarse = ((extent.x * extent.y * extent.z * k as f32 / photons.len() as f32).cbrt()).max(0.1 * r_max);
    let cells: Vec<f32> = (0..=FINER_GRIDS).map(|l| coarse / (1u32 << l) as f32).collect();
    let key = |p: Vec3, cell: f32| {
        let c = ((p - lo) / cell).floor();
        (c.x as i32, c.y as i32, c.z as i32)
    };
    let grids: Vec<HashMap<(i32, i32, i32), u32>> = cells
        .par_iter()
        .map(|&cell| {
            let mut counts = HashMap::with_capacity(photons.len() / k.max(1) + 1);
            for p in photons {
                *counts.entry(key(p.pos, cell)).or_insert(0u32) += 1;
            }
            counts
        })
        .collect();
    let block = |p: Vec3, level: usize| {
        let (x, y, z) = key(p, cells[level]);
        let mut n = 0u32;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    n += grids[level].get(&(x + dx, y + dy, z + dz)).copied().unwrap_or(0);
                }
            }
        }
        n
    };
    let r2_max = r_max * r_max;
    photons
        .par_iter()
        .map(|p| {
            // The finest grid whose 27 cells about the photon still hold k
            // photons: a block about as wide as the sphere of k photons
            // there, as a k-nearest search would find it.
            let mut level = 0;
            let mut n = block(p.pos, 0);
            while level < FINER_GRIDS {
                let finer = block(p.pos, level + 1);
                if (finer as usize) < k {
                    break;
                }
                (level, n) = (level + 1, finer);
            }
            let cell = cells[level];
            let density = n as f32 / (27.0 * cell * cell * cell);
            // (4/3) π r³ density = k.
            let r = (3.0 * k as f32 / (4.0 * std::f32::consts::PI * density)).cbrt();
            let r2 = if r.is_finite() { (r * r).min(r2_max) } else { r2_max };
            (r2 * shrink * shrink).max(1e-12)
        })
        .collect()
}

/// Photons per leaf of the hierarchy. The spheres overlap heavily (a
/// camera ray through fog crosses hundreds of them), so a ray visits many
/// nodes per photon it collects, and a node costs more than a photon's
/// test: 32 per leaf made 13-volume-caustic's camera pass 1.3 times faster
/// than 4 (100 x 100, 4 spp, --integrator photon, medians of three).
const LEAF: usize = 32;

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// A leaf: photons `first..first + count`; an inner node
    /// (`count == 0`): children `first` and `first + 1`.
    first: u32,
    count: u32,
}

/// A volume photon map with each photon's radius.
#[derive(Debug, Default)]
pub struct VolumeMap {
    photons: Vec<VolumePhoton>,
    radii2: Vec<f32>,
    nodes: Vec<Node>,
}

/// A photon a ray crossed: where along the ray its centre projects, and
/// its kernel there (1 / (π r²)).
#[derive(Clone, Copy, Debug)]
pub struct Crossed<'a> {
    pub photon: &'a VolumePhoton,
    pub t: f32,
    pub kernel: f32,
}

impl VolumeMap {
    /// The map of `photons`, each photon's radius that of the sphere
    /// that holds `k` photons at the density around it, at most `r_max`,
    /// times `shrink` (a progressive pass's narrowing; 1 in a classic
    /// render). The density is counted in a grid of cells that hold about
    /// `k` photons each on average, over the 27 cells about the photon's:
    /// linear in the photons (a k-nearest search per photon cost 30 times
    /// more), and smoother than the k-th neighbour's distance.
    pub fn build(photons: Vec<VolumePhoton>, k: usize, r_max: f32, shrink: f32) -> Self {
        if photons.is_empty() {
            return VolumeMap::default();
        }
        let radii2 = radii(&photons, k, r_max, shrink);
        let mut map = VolumeMap { photons, radii2, nodes: Vec::new() };
        let mut order: Vec<u32> = (0..map.photons.len() as u32).collect();
        map.nodes.push(Node { bounds: Aabb { lo: Vec3::ZERO, hi: Vec3::ZERO }, first: 0, count: 0 });
        map.split(0, &mut order, 0);
        map.photons = order.iter().map(|&i| map.photons[i as usize]).collect();
        map.radii2 = order.iter().map(|&i| map.radii2[i as usize]).collect();
        map
    }

    /// Fills node `node` with the photons `order` (at `offset` in the
    /// final order), splitting at the median of its longest axis.
    fn split(&mut self, node: usize, order: &mut [u32], offset: usize) {
        let sphere = |i: u32| {
            let (p, r) = (self.photons[i as usize].pos, self.radii2[i as usize].sqrt());
            (p - Vec3::splat(r), p + Vec3::splat(r))
        };
        let (lo, hi) = order
            .iter()
            .map(|&i| sphere(i))
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(a, b), (l, h)| (a.min(l), b.max(h)));
        self.nodes[node].bounds = Aabb { lo, hi };
        if order.len() <= LEAF {
            self.nodes[node].first = offset as u32;
            self.nodes[node].count = order.len() as u32;
            return;
        }
        let extent = hi - lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = order.len() / 2;
        let photons = &self.photons;
        order.select_nth_unstable_by(mid, |&a, &b| {
            photons[a as usize].pos[axis].total_cmp(&photons[b as usize].pos[axis]).then(a.cmp(&b))
        });
        let first = self.nodes.len();
        self.nodes[node].first = first as u32;
        let empty = Node { bounds: Aabb { lo: Vec3::ZERO, hi: Vec3::ZERO }, first: 0, count: 0 };
        self.nodes.push(empty);
        self.nodes.push(empty);
        let (left, right) = order.split_at_mut(mid);
        self.split(first, left, offset);
        self.split(first + 1, right, offset + mid);
    }

    pub fn len(&self) -> usize {
        self.photons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    pub fn memory_bytes(&self) -> usize {
        self.photons.len() * (std::mem::size_of::<VolumePhoton>() + 4) + self.nodes.len() * std::mem::size_of::<Node>()
    }

    /// Calls `f` with every photon whose sphere the segment of `ray` over
    /// [0, `t_max`] crosses with its centre's projection inside it, in
    /// the map's order (the same on every thread).
    pub fn beam(&self, ray: &Ray, t_max: f32, mut f: impl FnMut(Crossed)) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = ray.dir.recip();
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if !node.bounds.crossed(ray.origin, inv, t_max) {
                continue;
            }
            if node.count == 0 {
                if top + 2 > stack.len() {
                    continue;
                }
                stack[top] = node.first + 1;
                stack[top + 1] = node.first;
                top += 2;
                continue;
            }
            for i in node.first as usize..(node.first + node.count) as usize {
                let p = &self.photons[i];
                let v = p.pos - ray.origin;
                let t = v.dot(ray.dir);
                if !(t >= 0.0 && t <= t_max) {
                    continue;
                }
                let d2 = (v.length_squared() - t * t).max(0.0);
                let r2 = self.radii2[i];
                if d2 < r2 {
                    f(Crossed { photon: p, t, kernel: 1.0 / (std::f32::consts::PI * r2) });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{stream, Domain};
    use rand::RngExt;

    /// The hierarchy finds exactly the photons a brute-force scan finds.
    #[test]
    fn beam_finds_what_brute_force_finds() {
        let mut rng = stream(7, Domain::Camera, 0);
        let photons: Vec<VolumePhoton> = (0..3000)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random());
                VolumePhoton::new(p, Color::ONE, Vec3::X, 0)
            })
            .collect();
        let map = VolumeMap::build(photons.clone(), 8, 0.2, 1.0);
        assert_eq!(map.len(), 3000);
        for j in 0..50 {
            let o = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::splat(0.5);
            let d = (Vec3::new(rng.random(), rng.random(), rng.random()) - Vec3::splat(0.5)).normalize();
            let ray = Ray::new(o, d);
            let t_max = 0.3 + j as f32 * 0.03;
            let mut got = Vec::new();
            map.beam(&ray, t_max, |c| got.push((c.photon.pos.to_array().map(f32::to_bits), c.t.to_bits())));
            let mut want = Vec::new();
            for (i, p) in map.photons.iter().enumerate() {
                let v = p.pos - o;
                let t = v.dot(d);
                if t >= 0.0 && t <= t_max && (v.length_squared() - t * t).max(0.0) < map.radii2[i] {
                    want.push((p.pos.to_array().map(f32::to_bits), t.to_bits()));
                }
            }
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want);
        }
    }

    /// With photons of total power Φ spread uniformly through a unit cube,
    /// the beam estimate along a line through it sums to Φ × length /
    /// volume on average (the 2D kernel integrates to one over its disk).
    #[test]
    fn beam_estimate_of_a_uniform_density() {
        let mut rng = stream(9, Domain::Camera, 1);
        let n = 200_000;
        let photons: Vec<VolumePhoton> = (0..n)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random());
                VolumePhoton::new(p, Color::splat(1.0 / n as f32), Vec3::Z, 0)
            })
            .collect();
        let map = VolumeMap::build(photons, 32, 0.1, 1.0);
        let mut sum = 0.0f64;
        let rays = 400;
        for _ in 0..rays {
            let (y, z) = (0.2 + 0.6 * rng.random::<f32>(), 0.2 + 0.6 * rng.random::<f32>());
            let ray = Ray::new(Vec3::new(0.2, y, z), Vec3::X);
            map.beam(&ray, 0.6, |c| sum += (c.photon.power.x * c.kernel) as f64);
        }
        let mean = sum / rays as f64;
        assert!((mean - 0.6).abs() < 0.03, "{mean}");
    }

    /// Where the photons crowd into a small part of their box (a volume
    /// caustic's cone in a room), a photon's sphere is about the one a
    /// k-nearest search gives it: the first grid's cells, sized for the
    /// photons spread evenly, span the whole crowd and gave these
    /// photons spheres about six times too wide.
    #[test]
    fn crowded_photons_get_the_k_nearest_radius() {
        let mut rng = stream(13, Domain::Camera, 3);
        let (k, sparse, crowd) = (24, 2000, 20_000);
        let room = Vec3::new(4.0, 4.0, 3.0);
        let mut photons: Vec<VolumePhoton> = (0..sparse)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random()) * room;
                VolumePhoton::new(p, Color::ONE, Vec3::Z, 0)
            })
            .collect();
        // A cylinder of radius 0.05 and length 1 along z.
        photons.extend((0..crowd).map(|_| {
            let (r, phi) = (0.05 * rng.random::<f32>().sqrt(), std::f32::consts::TAU * rng.random::<f32>());
            let p = Vec3::new(2.0 + r * phi.cos(), 2.0 + r * phi.sin(), 1.0 + rng.random::<f32>());
            VolumePhoton::new(p, Color::ONE, Vec3::Z, 0)
        }));
        let r2 = radii(&photons, k, 0.5, 1.0);
        let mut ratios: Vec<f32> = (sparse..sparse + crowd)
            .step_by(100)
            .map(|i| {
                let mut d2: Vec<f32> = photons.iter().map(|q| (q.pos - photons[i].pos).length_squared()).collect();
                d2.select_nth_unstable_by(k, f32::total_cmp);
                (r2[i] / d2[k]).sqrt()
            })
            .collect();
        ratios.sort_unstable_by(f32::total_cmp);
        let median = ratios[ratios.len() / 2];
        assert!((0.7..1.6).contains(&median), "radius over the k-nearest distance: {median}");
    }

    /// A segment that ends where the medium ends (a wall) reads the
    /// density there without bias: with photons of total power Φ uniform
    /// through a unit cube, segments of length 0.05 that end on its face
    /// (or start there) sum to Φ × 0.05 on average. A photon counts where
    /// its centre's projection lies on the segment, so the kernels are a
    /// cylinder about the segment that ends with it, however far a photon's
    /// sphere reaches past the wall; counting every photon whose sphere
    /// meets the segment would read about 2r/3 of the density more at each
    /// end the medium goes on past (r ≈ 0.05 here: about +70%).
    #[test]
    fn beam_estimate_stops_at_the_medium_s_end() {
        let mut rng = stream(11, Domain::Camera, 2);
        let n = 100_000;
        let photons: Vec<VolumePhoton> = (0..n)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random());
                VolumePhoton::new(p, Color::splat(1.0 / n as f32), Vec3::Z, 0)
            })
            .collect();
        let map = VolumeMap::build(photons, 64, 0.2, 1.0);
        let rays = 4000;
        for (start, dir) in [(0.95, Vec3::X), (0.05, -Vec3::X)] {
            let mut sum = 0.0f64;
            for _ in 0..rays {
                let (y, z) = (0.2 + 0.6 * rng.random::<f32>(), 0.2 + 0.6 * rng.random::<f32>());
                let ray = Ray::new(Vec3::new(start, y, z), dir);
                map.beam(&ray, 0.05, |c| sum += (c.photon.power.x * c.kernel) as f64);
            }
            let mean = sum / rays as f64;
            println!("from {start} along {dir}: {mean} against 0.05");
            assert!((mean / 0.05 - 1.0).abs() < 0.05, "from {start} along {dir}: {mean} against 0.05");
        }
    }
}
