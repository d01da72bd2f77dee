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

/// Where a scene's volume caustic photons are read by the beam estimate:
/// those whose sphere is narrower than this times the sphere that holds k
/// photons at their mean density over their box (those denser than the
/// mean). The sparser ones are the light the glass scatters about the
/// room, whose wide spheres a camera segment crosses by the hundred: in
/// 13-volume-caustic's default command a sixth of the photons and most of
/// the beam estimate's time (20 s of 24 s user CPU, of the render's 73 s);
/// read from the global volume photons' grid instead (whose cost is the
/// cells crossed; there its cells are a third of their spheres' radius)
/// the image is the same within its noise. Reading all of them there (0) blurs the cone
/// the glass focuses (its window -0.6% and -1.9% against +0.2% and -0.6%)
/// for a tenth more time saved.
pub const SPARSE_RADIUS: f32 = 1.0;

/// The squared radius of each photon of `photons` (see [`VolumeMap::build`]),
/// and the radius of the sphere that holds `k` photons at their mean
/// density over their bounding box (before the cap and `shrink`).
fn radii_and_mean(photons: &[VolumePhoton], k: usize, r_max: f32, shrink: f32) -> (Vec<f32>, f32) {
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
    let mean_density = photons.len() as f32 / (extent.x * extent.y * extent.z);
    let r_mean = (3.0 * k as f32 / (4.0 * std::f32::consts::PI * mean_density)).cbrt();
    let r2 = photons
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
        .collect();
    (r2, r_mean)
}

#[cfg(test)]
fn radii(photons: &[VolumePhoton], k: usize, r_max: f32, shrink: f32) -> Vec<f32> {
    radii_and_mean(photons, k, r_max, shrink).0
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
    /// The photons' positions and squared radii again, one array per
    /// coordinate and [`LANES`] entries longer (radius² -1: never crossed),
    /// so a leaf's test reads [`LANES`] photons at once: a ray tests
    /// about six times as many photons as it crosses (13-volume-caustic:
    /// 1950 tested, 328 crossed a call), and one at a time the test was a
    /// branch mispredicted every few photons.
    lanes: [Vec<f32>; 4],
    nodes: Vec<Node>,
}

/// Photons a leaf's test takes at once (one AVX register of f32).
const LANES: usize = 8;

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
        let radii2 = radii_and_mean(&photons, k, r_max, shrink).0;
        Self::from_radii(photons, radii2)
    }

    /// The map of the photons of `photons` whose sphere (as
    /// [`Self::build`] sizes it) is narrower than `sparse` times the
    /// sphere of k photons at their mean density, and the others.
    pub fn build_dense(
        photons: Vec<VolumePhoton>,
        k: usize,
        r_max: f32,
        shrink: f32,
        sparse: f32,
    ) -> (Self, Vec<VolumePhoton>) {
        if photons.is_empty() {
            return (VolumeMap::default(), Vec::new());
        }
        let (radii2, r_mean) = radii_and_mean(&photons, k, r_max, shrink);
        let limit = (sparse * r_mean * shrink).powi(2);
        let (mut dense, mut dense_r2, mut rest) = (Vec::new(), Vec::new(), Vec::new());
        for (p, r2) in photons.into_iter().zip(radii2) {
            if r2 < limit {
                dense.push(p);
                dense_r2.push(r2);
            } else {
                rest.push(p);
            }
        }
        if dense.is_empty() {
            return (VolumeMap::default(), rest);
        }
        (Self::from_radii(dense, dense_r2), rest)
    }

    fn from_radii(photons: Vec<VolumePhoton>, radii2: Vec<f32>) -> Self {
        let mut map = VolumeMap { photons, radii2, lanes: Default::default(), nodes: Vec::new() };
        let mut order: Vec<u32> = (0..map.photons.len() as u32).collect();
        map.nodes.push(Node { bounds: Aabb { lo: Vec3::ZERO, hi: Vec3::ZERO }, first: 0, count: 0 });
        map.split(0, &mut order, 0);
        map.photons = order.iter().map(|&i| map.photons[i as usize]).collect();
        map.radii2 = order.iter().map(|&i| map.radii2[i as usize]).collect();
        let pad = |mut v: Vec<f32>, with: f32| {
            v.extend([with; LANES]);
            v
        };
        map.lanes = [
            pad(map.photons.iter().map(|p| p.pos.x).collect(), 0.0),
            pad(map.photons.iter().map(|p| p.pos.y).collect(), 0.0),
            pad(map.photons.iter().map(|p| p.pos.z).collect(), 0.0),
            pad(map.radii2.clone(), -1.0),
        ];
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
        self.photons.len() * (std::mem::size_of::<VolumePhoton>() + 4)
            + self.lanes.iter().map(|l| l.len() * 4).sum::<usize>()
            + self.nodes.len() * std::mem::size_of::<Node>()
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
            let end = (node.first + node.count) as usize;
            for base in (node.first as usize..end).step_by(LANES) {
                // Lanes past the leaf's end read the next leaf's photons
                // (or the padding) and are masked off.
                let mut crossed = self.crossed_lanes(base, ray, t_max) & (u32::MAX >> (32 - (end - base).min(LANES)));
                while crossed != 0 {
                    let i = base + crossed.trailing_zeros() as usize;
                    crossed &= crossed - 1;
                    let p = &self.photons[i];
                    let t = (p.pos - ray.origin).dot(ray.dir);
                    f(Crossed { photon: p, t, kernel: 1.0 / (std::f32::consts::PI * self.radii2[i]) });
                }
            }
        }
    }

    /// Bit j set where photon `base + j` (j < [`LANES`]) has its centre's
    /// projection on the segment over [0, `t_max`] and its sphere crossed
    /// by it: [`Self::crossed_lanes_scalar`]'s test, eight lanes at once
    /// where the build's CPU has AVX. Each lane's arithmetic is the scalar
    /// test's in the same order (no fused multiply-adds, NaN lost in the
    /// max as `f32::max` loses it), so both find the same photons.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    #[inline]
    fn crossed_lanes(&self, base: usize, ray: &Ray, t_max: f32) -> u32 {
        use std::arch::x86_64::*;
        let [xs, ys, zs, rs] = &self.lanes;
        let (xs, ys, zs, rs) =
            (&xs[base..base + LANES], &ys[base..base + LANES], &zs[base..base + LANES], &rs[base..base + LANES]);
        let (o, d) = (ray.origin, ray.dir);
        // SAFETY: the slices hold LANES floats each (checked above), and
        // the build's target has AVX (the cfg).
        unsafe {
            let vx = _mm256_sub_ps(_mm256_loadu_ps(xs.as_ptr()), _mm256_set1_ps(o.x));
            let vy = _mm256_sub_ps(_mm256_loadu_ps(ys.as_ptr()), _mm256_set1_ps(o.y));
            let vz = _mm256_sub_ps(_mm256_loadu_ps(zs.as_ptr()), _mm256_set1_ps(o.z));
            let dot = |a: __m256, b: __m256, c: __m256, e: __m256, f: __m256, g: __m256| {
                _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a, e), _mm256_mul_ps(b, f)), _mm256_mul_ps(c, g))
            };
            let t = dot(vx, vy, vz, _mm256_set1_ps(d.x), _mm256_set1_ps(d.y), _mm256_set1_ps(d.z));
            let d2 =
                _mm256_max_ps(_mm256_sub_ps(dot(vx, vy, vz, vx, vy, vz), _mm256_mul_ps(t, t)), _mm256_setzero_ps());
            let hit = _mm256_and_ps(
                _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_GE_OQ>(t, _mm256_setzero_ps()),
                    _mm256_cmp_ps::<_CMP_LE_OQ>(t, _mm256_set1_ps(t_max)),
                ),
                _mm256_cmp_ps::<_CMP_LT_OQ>(d2, _mm256_loadu_ps(rs.as_ptr())),
            );
            _mm256_movemask_ps(hit) as u32
        }
    }

    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
    #[inline]
    fn crossed_lanes(&self, base: usize, ray: &Ray, t_max: f32) -> u32 {
        self.crossed_lanes_scalar(base, ray, t_max)
    }

    /// [`Self::crossed_lanes`] one photon at a time, glam's dot product
    /// written out.
    #[cfg_attr(all(target_arch = "x86_64", target_feature = "avx"), allow(dead_code))]
    fn crossed_lanes_scalar(&self, base: usize, ray: &Ray, t_max: f32) -> u32 {
        let [xs, ys, zs, rs] = &self.lanes;
        let (o, d) = (ray.origin, ray.dir);
        let mut mask = 0u32;
        for j in 0..LANES {
            let i = base + j;
            let (vx, vy, vz) = (xs[i] - o.x, ys[i] - o.y, zs[i] - o.z);
            let t = vx * d.x + vy * d.y + vz * d.z;
            let d2 = (vx * vx + vy * vy + vz * vz - t * t).max(0.0);
            if t >= 0.0 && t <= t_max && d2 < rs[i] {
                mask |= 1 << j;
            }
        }
        mask
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{stream, Domain, Rng};
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

    /// `sparse` photons of power one spread through a 4 x 4 x 3 room, then
    /// `crowd` of power `crowd_power` in a cylinder of radius 0.05 and
    /// length 1 along z at its middle (a volume caustic's cone).
    fn crowd_in_a_room(rng: &mut Rng, sparse: usize, crowd: usize, crowd_power: f32) -> Vec<VolumePhoton> {
        let room = Vec3::new(4.0, 4.0, 3.0);
        let mut photons: Vec<VolumePhoton> = (0..sparse)
            .map(|_| {
                let p = Vec3::new(rng.random(), rng.random(), rng.random()) * room;
                VolumePhoton::new(p, Color::ONE, Vec3::Z, 0)
            })
            .collect();
        photons.extend((0..crowd).map(|_| {
            let (r, phi) = (0.05 * rng.random::<f32>().sqrt(), std::f32::consts::TAU * rng.random::<f32>());
            let p = Vec3::new(2.0 + r * phi.cos(), 2.0 + r * phi.sin(), 1.0 + rng.random::<f32>());
            VolumePhoton::new(p, Color::splat(crowd_power), Vec3::Z, 0)
        }));
        photons
    }

    /// Where the photons crowd into a small part of their box (a volume
    /// caustic's cone in a room), a photon's sphere is about the one a
    /// k-nearest search gives it: the first grid's cells, sized for the
    /// photons spread evenly, span the whole crowd and gave these
    /// photons spheres about six times too wide.
    #[test]
    fn crowded_photons_get_the_k_nearest_radius() {
        let (k, sparse, crowd) = (24, 2000, 20_000);
        let photons = crowd_in_a_room(&mut stream(13, Domain::Camera, 3), sparse, crowd, 1.0);
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

    /// `build_dense` keeps every photon once: those of the crowd (a
    /// volume caustic's cone) in the map with the radii `build` gives
    /// them, most of the sparse ones about it handed back.
    #[test]
    fn dense_photons_stay_in_the_map_and_sparse_ones_are_handed_back() {
        let (k, sparse, crowd) = (24, 2000, 20_000);
        let photons = crowd_in_a_room(&mut stream(17, Domain::Camera, 4), sparse, crowd, 2.0);
        let whole = VolumeMap::build(photons.clone(), k, 0.5, 0.5);
        let (map, rest) = VolumeMap::build_dense(photons.clone(), k, 0.5, 0.5, 1.0);
        assert_eq!(map.len() + rest.len(), photons.len());
        let in_map = map.photons.iter().filter(|p| p.power.x == 2.0).count();
        assert_eq!(in_map, crowd, "every photon of the crowd stays in the map");
        assert!(rest.len() > sparse * 9 / 10, "{} of {sparse} sparse photons handed back", rest.len());
        assert!(rest.iter().all(|p| p.power.x == 1.0));
        // The map's photons keep the radii the whole map gives them.
        let radius = |m: &VolumeMap, p: &VolumePhoton| {
            let i = m.photons.iter().position(|q| q.pos == p.pos).unwrap();
            m.radii2[i]
        };
        for p in map.photons.iter().step_by(997) {
            assert_eq!(radius(&map, p), radius(&whole, p));
        }
        // Nothing sparse: the map is `build`'s.
        let (all, none) = VolumeMap::build_dense(photons.clone(), k, 0.5, 1.0, f32::INFINITY);
        assert!(none.is_empty());
        assert_eq!(all.radii2, VolumeMap::build(photons, k, 0.5, 1.0).radii2);
    }

    /// The leaf test eight photons at a time finds what the scalar one
    /// finds, rays through the photons and along their planes included.
    #[test]
    fn lanes_agree_with_the_scalar_test() {
        let mut rng = stream(19, Domain::Camera, 5);
        let photons: Vec<VolumePhoton> = (0..2000)
            .map(|i| {
                let mut p = Vec3::new(rng.random(), rng.random(), rng.random());
                if i % 7 == 0 {
                    p.y = 0.5;
                }
                VolumePhoton::new(p, Color::ONE, Vec3::X, 0)
            })
            .collect();
        let map = VolumeMap::build(photons, 8, 0.2, 1.0);
        let mut found = 0;
        for j in 0..300 {
            let o = Vec3::new(rng.random(), rng.random(), rng.random());
            let d = match j % 3 {
                0 => Vec3::X,
                _ => (Vec3::new(rng.random(), rng.random(), rng.random()) - Vec3::splat(0.5)).normalize(),
            };
            let ray = Ray::new(if j % 3 == 0 { Vec3::new(o.x, 0.5, o.z) } else { o }, d);
            let t_max = 0.1 + rng.random::<f32>();
            for base in 0..map.len() {
                let got = map.crossed_lanes(base, &ray, t_max);
                assert_eq!(got, map.crossed_lanes_scalar(base, &ray, t_max));
                found += got.count_ones();
            }
        }
        assert!(found > 10_000, "{found}");
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
