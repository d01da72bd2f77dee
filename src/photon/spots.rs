//! Bright spots: the parts of the scene's surfaces whose irradiance far
//! exceeds the scene's mean (a caustic's focus, a sunlit patch), found among
//! the irradiance cache's points and each bounded by a sphere.
//!
//! Seen from elsewhere such a spot is a small, bright secondary light: a
//! cosine gather ray meets it rarely and then carries a large value, an
//! isolated bright pixel. Final gathering aims a few rays at the spots
//! (`integrator::aim`), weighed so that no light is counted twice.

use crate::math::Frame;
use crate::sampling::Discrete;
use glam::{IVec3, Vec2, Vec3};
use std::collections::HashMap;

/// A point is part of a spot where its irradiance exceeds the scene's
/// area-weighted mean irradiance this many times. A cosine gather ray that
/// meets a spot carries its radiance divided by the rays per hit (4 by
/// default); at 8x the mean that alone is twice a typical pixel's value,
/// the start of what the speckle count calls a speckle (4x the median).
pub const SPOT_CONTRAST: f32 = 8.0;

/// The brightest spots kept (by power): gather rays choose among those a
/// point sees, and each costs a cone test per gather ray.
pub const MAX_SPOTS: usize = 16;

/// A spot whose cap is at most this deep, relative to its radius, is
/// flat: aimed at through its plane ([`PatchMap`]), not its sphere.
pub const SHALLOW_SPOT: f32 = 0.05;

/// Cells a side of a flat spot's [`PatchMap`].
pub const PATCH_CELLS: usize = 32;

/// A point of the irradiance cache as the spots see it.
#[derive(Clone, Copy, Debug)]
pub struct SpotPoint {
    pub position: Vec3,
    /// The surface's normal, on the side the light arrived from.
    pub normal: Vec3,
    /// Irradiance, the mean of its channels.
    pub irradiance: f32,
    /// The squared radius of the area the point stands for (up to a
    /// constant: the radius its estimate needed).
    pub r2: f32,
}

/// A bright spot: its bounding sphere, the side it is lit from (the mean
/// of its points' normals), how far behind its mean plane it may still be
/// seen from, the power its points stand for, and, for a flat spot, its
/// irradiance over its plane.
#[derive(Clone, Debug, PartialEq)]
pub struct Spot {
    pub center: Vec3,
    pub radius: f32,
    pub normal: Vec3,
    /// Zero for a flat spot; for a cap of a curved surface, the cap's depth
    /// below its rim, which grows with the normals' spread (a cap of
    /// half-angle t has mean normal length ~1 - t^2/4 and depth ~r t / 2).
    pub behind: f32,
    pub power: f32,
    pub patch: Option<PatchMap>,
}

impl Spot {
    /// Whether light leaving the spot can reach `x`: `x` lies in front of
    /// its mean plane (or, for a spot on a curved surface, not too far
    /// behind it). The outside of a sunlit wall is the brightest spot of a
    /// room lit through its window, and never seen from inside; points in
    /// the spot's own plane would only graze it.
    pub fn faces(&self, x: Vec3) -> bool {
        (x - self.center).dot(self.normal) > 1e-3 * self.radius - self.behind
    }
}

/// The spots among `points`: points at least [`SPOT_CONTRAST`] times the
/// area-weighted mean irradiance, joined where they face the same way
/// (dominant axis and sign of the normal) and lie in the same or
/// neighbouring cells of a grid twice their median radius wide; the
/// [`MAX_SPOTS`] most powerful, most powerful first. Each flat one gets
/// its [`PatchMap`] from `irradiance(x, n)`, the irradiance (mean of the
/// channels) at `x` on a surface facing `n`.
///
/// `points` is read twice and never held whole (an irradiance cache of
/// 1e7 photons has ~3 million points): the median needs 8 bytes a point.
pub fn bright_spots(
    points: impl Iterator<Item = SpotPoint> + Clone,
    irradiance: impl Fn(Vec3, Vec3) -> f32,
) -> Vec<Spot> {
    let valid = |p: &SpotPoint| {
        p.position.is_finite() && p.normal.is_finite() && p.irradiance.is_finite() && p.r2.is_finite() && p.r2 > 0.0
    };
    // The area-weighted median irradiance: what most of the surfaces get.
    let mut by_irradiance: Vec<(f32, f32)> = points.clone().filter(valid).map(|p| (p.irradiance, p.r2)).collect();
    by_irradiance.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let area: f64 = by_irradiance.iter().map(|p| p.1 as f64).sum();
    let mut below = 0.0;
    let Some(&(median, _)) = by_irradiance.iter().find(|p| {
        below += p.1 as f64;
        below >= 0.5 * area
    }) else {
        return Vec::new();
    };
    drop(by_irradiance);
    let threshold = SPOT_CONTRAST * median;
    if !(threshold > 0.0) {
        return Vec::new();
    }
    let hot: Vec<SpotPoint> = points.filter(valid).filter(|p| p.irradiance > threshold).collect();
    if hot.is_empty() {
        return Vec::new();
    }
    let mut r2: Vec<f32> = hot.iter().map(|p| p.r2).collect();
    r2.sort_unstable_by(f32::total_cmp);
    let cell = 2.0 * r2[r2.len() / 2].sqrt();
    let key = |p: &SpotPoint| ((p.position / cell).floor().as_ivec3(), facing_class(p.normal));
    let mut cells: HashMap<(IVec3, u8), usize> = HashMap::new();
    let mut parent: Vec<usize> = (0..hot.len()).collect();
    for (i, p) in hot.iter().enumerate() {
        let first = *cells.entry(key(p)).or_insert(i);
        union(&mut parent, first, i);
    }
    let keys: Vec<((IVec3, u8), usize)> = cells.iter().map(|(&k, &i)| (k, i)).collect();
    for ((k, class), i) in keys {
        for d in neighbours() {
            if let Some(&j) = cells.get(&(k + d, class)) {
                union(&mut parent, i, j);
            }
        }
    }
    // Per cluster: its box (for the centre), its normals' area-weighted
    // sum, its area and power, its positions' area-weighted sum (a point
    // of its mean plane).
    let mut clusters: HashMap<usize, (Vec3, Vec3, Vec3, f32, f32, Vec3)> = HashMap::new();
    for (i, p) in hot.iter().enumerate() {
        let root = find(&mut parent, i);
        let r = p.r2.sqrt();
        let c = clusters.entry(root).or_insert((p.position - r, p.position + r, Vec3::ZERO, 0.0, 0.0, Vec3::ZERO));
        c.0 = c.0.min(p.position - r);
        c.1 = c.1.max(p.position + r);
        c.2 += p.normal * p.r2;
        c.3 += p.r2;
        c.4 += p.irradiance * p.r2;
        c.5 += p.position * p.r2;
    }
    let mut radius: HashMap<usize, f32> = HashMap::new();
    for (i, p) in hot.iter().enumerate() {
        let root = find(&mut parent, i);
        let (lo, hi, ..) = clusters[&root];
        let reach = p.position.distance(0.5 * (lo + hi)) + p.r2.sqrt();
        let r = radius.entry(root).or_insert(0.0);
        *r = r.max(reach);
    }
    let mut spots: Vec<Spot> = clusters
        .iter()
        .map(|(root, &(lo, hi, normal, area, power, sum))| {
            let spread = (1.0 - normal.length() / area).max(0.0);
            let radius = radius[root];
            Spot {
                center: 0.5 * (lo + hi),
                radius,
                normal: normal.normalize_or_zero(),
                behind: radius * spread.sqrt(),
                power,
                patch: None,
            }
            .with_patch(sum / area, &irradiance)
        })
        .collect();
    // Ties broken by position: the same spots whatever the hash order.
    spots.sort_by(|a, b| {
        b.power
            .total_cmp(&a.power)
            .then_with(|| a.center.to_array().partial_cmp(&b.center.to_array()).unwrap_or(std::cmp::Ordering::Equal))
    });
    spots.truncate(MAX_SPOTS);
    spots
}

impl Spot {
    /// Whether the spot is flat: its cap at most [`SHALLOW_SPOT`] of its
    /// radius deep.
    fn is_flat(&self) -> bool {
        self.behind <= SHALLOW_SPOT * self.radius && self.normal != Vec3::ZERO
    }

    /// The spot with its [`PatchMap`], if flat, over the plane through
    /// `on_plane` facing its normal.
    fn with_patch(mut self, on_plane: Vec3, irradiance: impl Fn(Vec3, Vec3) -> f32) -> Self {
        if self.is_flat() {
            let center = self.center - (self.center - on_plane).dot(self.normal) * self.normal;
            self.patch = PatchMap::build(center, self.normal, self.radius, |x| irradiance(x, self.normal));
        }
        self
    }
}

/// A flat spot's irradiance over the square of side 2 r around its centre
/// in its plane, [`PATCH_CELLS`] cells a side: a piecewise-constant
/// density over the plane, proportional to the light each cell sends out.
/// Final gathering aims at points drawn from it: a sunlit patch is a
/// parallelogram that fills a third of its bounding disk, a caustic's focus
/// a small part of it, and a point uniform on the disk would mostly meet
/// the dim floor around them.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchMap {
    square: Square,
    /// The cells, row by row, by their weights.
    cells: Discrete,
}

/// The square of a [`PatchMap`], with coordinates in cells from a corner.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Square {
    center: Vec3,
    frame: Frame,
    half: f32,
}

impl Square {
    fn cell(&self) -> f32 {
        2.0 * self.half / PATCH_CELLS as f32
    }

    /// The point of the plane at (`x`, `y`) cells from the corner.
    fn point(&self, x: f32, y: f32) -> Vec3 {
        let (x, y) = (x * self.cell() - self.half, y * self.cell() - self.half);
        self.center + self.frame.s * x + self.frame.t * y
    }

    /// The cell holding `p`, a point of the plane, if the square does.
    fn cell_of(&self, p: Vec3) -> Option<usize> {
        let d = p - self.center;
        let (x, y) = ((d.dot(self.frame.s) + self.half) / self.cell(), (d.dot(self.frame.t) + self.half) / self.cell());
        if !(x >= 0.0 && y >= 0.0 && x < PATCH_CELLS as f32 && y < PATCH_CELLS as f32) {
            return None;
        }
        Some((y as usize).min(PATCH_CELLS - 1) * PATCH_CELLS + (x as usize).min(PATCH_CELLS - 1))
    }
}

impl PatchMap {
    /// Each cell weighed by the mean of `irradiance` at four points in it;
    /// None where no cell has any (or the square is degenerate).
    pub fn build(center: Vec3, normal: Vec3, radius: f32, irradiance: impl Fn(Vec3) -> f32) -> Option<Self> {
        if !(radius > 0.0) || !radius.is_finite() || !center.is_finite() {
            return None;
        }
        let square = Square { center, frame: Frame::from_normal(normal), half: radius };
        let weights = (0..PATCH_CELLS * PATCH_CELLS).map(|i| {
            let (ix, iy) = ((i % PATCH_CELLS) as f32, (i / PATCH_CELLS) as f32);
            [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
                .iter()
                .map(|&(fx, fy)| irradiance(square.point(ix + fx, iy + fy)) as f64)
                .filter(|e| e.is_finite() && *e > 0.0)
                .sum::<f64>()
        });
        Some(PatchMap { square, cells: Discrete::new(weights)? })
    }

    pub fn center(&self) -> Vec3 {
        self.square.center
    }

    pub fn normal(&self) -> Vec3 {
        self.square.frame.n
    }

    /// A point of the plane drawn from the density (`u` uniform in [0, 1)^2).
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (i, fx) = self.cells.sample(u.x);
        self.square.point((i % PATCH_CELLS) as f32 + fx, (i / PATCH_CELLS) as f32 + u.y)
    }

    /// The density per unit area at `p`, a point of the plane.
    pub fn area_pdf(&self, p: Vec3) -> f32 {
        let cell = self.square.cell();
        self.square.cell_of(p).map_or(0.0, |i| self.cells.prob(i) / (cell * cell))
    }
}

/// The dominant axis and sign of a normal: points on surfaces that face
/// apart (the two sides of a wall, a floor and the wall beside it) are
/// never one spot.
fn facing_class(n: Vec3) -> u8 {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + (n[axis as usize] < 0.0) as u8
}

fn neighbours() -> impl Iterator<Item = IVec3> {
    (-1..=1).flat_map(|x| (-1..=1).flat_map(move |y| (-1..=1).map(move |z| IVec3::new(x, y, z))))
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (a, b) = (find(parent, a), find(parent, b));
    if a != b {
        parent[a.max(b)] = a.min(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dim floor of unit squares with two bright patches: two spots,
    /// the brighter first, each bounding its own patch and nothing else.
    #[test]
    fn two_bright_patches_on_a_dim_floor_are_two_spots() {
        let mut points = Vec::new();
        for i in 0..100 {
            for j in 0..100 {
                let x = Vec3::new(i as f32 * 0.1, 0.0, j as f32 * 0.1);
                let in_a = x.distance(Vec3::new(2.0, 0.0, 2.0)) < 0.3;
                let in_b = x.distance(Vec3::new(7.0, 0.0, 6.0)) < 0.5;
                let e = if in_a {
                    200.0
                } else if in_b {
                    100.0
                } else {
                    1.0
                };
                // Bright points stand for smaller areas (denser photons).
                let r2 = if in_a || in_b { 0.0025 } else { 0.01 };
                points.push(SpotPoint { position: x, normal: Vec3::Y, irradiance: e, r2 });
            }
        }
        let spots = bright_spots(points.iter().copied(), |_, _| 1.0);
        assert_eq!(spots.len(), 2, "{spots:?}");
        // The wider one has the more power.
        assert!(spots[0].center.distance(Vec3::new(7.0, 0.0, 6.0)) < 0.1, "{spots:?}");
        assert!(spots[1].center.distance(Vec3::new(2.0, 0.0, 2.0)) < 0.1, "{spots:?}");
        assert!((0.5..0.7).contains(&spots[0].radius), "{spots:?}");
        assert!((0.3..0.5).contains(&spots[1].radius), "{spots:?}");
        assert!(spots[0].normal.distance(Vec3::Y) < 1e-5);
        assert!(spots[0].faces(Vec3::new(0.0, 1.0, 0.0)) && !spots[0].faces(Vec3::new(0.0, -0.01, 0.0)));
        assert_eq!(spots[0].behind, 0.0);
    }

    /// The two sides of a thin wall, both bright: two spots, each lit
    /// from its own side.
    #[test]
    fn the_two_sides_of_a_wall_are_two_spots() {
        let mut points = Vec::new();
        for i in 0..400 {
            let x = Vec3::new((i % 20) as f32 * 0.1, 0.0, (i / 20) as f32 * 0.1);
            for (normal, e) in [(Vec3::Y, 50.0), (-Vec3::Y, 30.0)] {
                points.push(SpotPoint { position: x + normal * 0.001, normal, irradiance: e, r2: 0.01 });
            }
        }
        points.extend((0..20_000).map(|i| SpotPoint {
            position: Vec3::new(10.0 + (i % 100) as f32, 5.0, (i / 100) as f32),
            normal: Vec3::Z,
            irradiance: 1.0,
            r2: 1.0,
        }));
        let spots = bright_spots(points.iter().copied(), |_, _| 1.0);
        assert_eq!(spots.len(), 2, "{spots:?}");
        assert!(spots[0].normal.distance(Vec3::Y) < 1e-5 && spots[1].normal.distance(-Vec3::Y) < 1e-5, "{spots:?}");
    }

    /// A sunlit parallelogram on a floor: the map's samples land on it
    /// (over 90% of them, for 28% of the square), its density integrates
    /// to one, and it is the density of its samples (E[1 / pdf] over the
    /// samples is the square's area).
    #[test]
    fn a_patch_map_draws_points_as_its_density_says() {
        let lit = |x: Vec3| {
            let (u, v) = (x.x - 0.5 * x.z, x.z);
            u.abs() < 0.4 && v.abs() < 0.7
        };
        let map = PatchMap::build(Vec3::ZERO, Vec3::Y, 1.0, |x| if lit(x) { 100.0 } else { 1.0 }).unwrap();
        let mut rng = crate::sampling::stream(3, crate::sampling::Domain::Camera, 0);
        let n = 200_000;
        let (mut on_patch, mut inverse) = (0, 0.0f64);
        for _ in 0..n {
            let x = map.sample(crate::sampling::next_2d(&mut rng));
            assert!(x.y.abs() < 1e-6 && x.x.abs() <= 1.0 + 1e-5 && x.z.abs() <= 1.0 + 1e-5, "{x}");
            let pdf = map.area_pdf(x);
            assert!(pdf > 0.0, "{x}");
            inverse += 1.0 / pdf as f64;
            on_patch += lit(x) as u32;
        }
        assert!((inverse / n as f64 - 4.0).abs() < 0.2, "{}", inverse / n as f64);
        assert!(on_patch as f64 > 0.9 * n as f64, "{on_patch}");
        let m = 400;
        let integral: f64 = (0..m * m)
            .map(|i| {
                let (a, b) = ((i % m) as f32 + 0.5, (i / m) as f32 + 0.5);
                map.area_pdf(Vec3::new(2.0 * a / m as f32 - 1.0, 0.0, 2.0 * b / m as f32 - 1.0)) as f64
            })
            .sum::<f64>()
            * 4.0
            / (m * m) as f64;
        assert!((integral - 1.0).abs() < 1e-3, "{integral}");
        assert_eq!(map.area_pdf(Vec3::new(1.5, 0.0, 0.0)), 0.0);
        assert!(PatchMap::build(Vec3::ZERO, Vec3::Y, 1.0, |_| 0.0).is_none());
    }

    #[test]
    fn a_uniform_or_empty_scene_has_no_spots() {
        let point = |position: Vec3, irradiance: f32| SpotPoint { position, normal: Vec3::Y, irradiance, r2: 1.0 };
        let points: Vec<_> = (0..1000).map(|i| point(Vec3::new(i as f32, 0.0, 0.0), 1.0 + (i % 3) as f32)).collect();
        assert!(bright_spots(points.into_iter(), |_, _| 1.0).is_empty());
        assert!(bright_spots(std::iter::empty(), |_, _| 1.0).is_empty());
        assert!(
            bright_spots([point(Vec3::NAN, 1.0), point(Vec3::ZERO, f32::INFINITY)].into_iter(), |_, _| 1.0).is_empty()
        );
    }
}
