//! Irradiance precomputed at a subset of the global photons (Christensen
//! 1999): final-gather rays read one nearby value instead of running a
//! k-nearest estimate each.

use super::facing::FacingTrees;
use super::map::{in_front, PhotonMap, Scratch, NORMAL_COSINE};
use super::morton::bounds;
use super::spots::SpotPoint;
use super::{normal_times_127, prefetch, quantize_normal, Photon};
use crate::math::Color;
use glam::Vec3;
use rayon::prelude::*;

/// How far off each other's plane (as a share of their distance) a lookup
/// and a cache point at different levels lie before a ray checks what lies
/// between them ([`IrradianceCache::level_apart`]): beyond rounding, and
/// below what a surface's bumps and a mesh's facets make.
const OFF_PLANE: f32 = 0.02;

/// How far such a ray's ends are lifted off their surfaces, as a share of
/// their distance: above the sagitta of a sphere between two points whose
/// normals differ by the widest angle a lookup admits (d / 8R of d with
/// d / R = 2 sin(θ/2) = 0.45 at [`NORMAL_COSINE`]: 0.056 d), but not over a
/// small object's shell (a lookup reaching 2.4 to a wall 0.6 beside a unit
/// sphere lifts its ends by 0.15).
const LIFT: f32 = 0.06;

/// How many hidden cache points a lookup passes over before it reads
/// nothing: where that many lie behind a surface, so do the rest.
pub const MAX_HIDDEN: usize = 3;

/// Grid cells of the irradiance cache's index, as a fraction of the lookup
/// radius (twice the median estimate radius over the surfaces' area).
const CELL_FRACTION: f32 = 0.75;

/// Irradiance precomputed at a subset of the global photons (Christensen
/// 1999): final-gather rays then read one nearby value instead of running a
/// k-nearest estimate each.
///
/// Gather rays land anywhere in the scene, so their lookups share no cache
/// lines, and a kd-tree nearest-neighbour search over the points cost ~1 µs
/// each (a quarter of the default camera pass, notes/performance.md). The
/// points are therefore also bucketed by the cell of a uniform grid (cells
/// hashed, each cell's points contiguous): a lookup reads its own cell's few
/// points and takes the one facing like the query nearest relative to its
/// reach ([`IrradianceCache::lookup`]); only where the
/// cell holds none does it search the trees.
pub struct IrradianceCache {
    points: Vec<CachePoint>,
    /// The points by facing class: a lookup whose cell holds no answer
    /// reads only the classes that may face like it. One tree over all
    /// points read, on a thin wall's unlit side, every point of its sunlit
    /// other side (the same plane) to keep none: in the sun-window scene,
    /// 92% of the points such lookups read faced away, and the camera pass
    /// spent more than half its time there.
    trees: FacingTrees,
    /// Each facing class's largest squared reach: how far a lookup in it
    /// may search.
    class_reach2: Vec<f32>,
    cells: CellIndex,
}

#[derive(Clone, Copy, Debug)]
struct CachePoint {
    position: [f32; 3],
    irradiance: [f32; 3],
    normal: [i8; 4],
    /// One over the squared distance within which the point answers a
    /// lookup, its reach: twice its own estimate's radius (capped at the
    /// radius cap); a lookup at squared distance d2 reads d2 * inv_reach2,
    /// the relative distance, which is at most 1 within reach. Per point,
    /// because photon density varies by orders of magnitude between the
    /// surfaces of one scene (a sunlit outside wall and the room behind
    /// it): one radius for all, fitted to the dense surfaces, left the
    /// sparse ones' lookups finding nothing (measured: a room lit through
    /// a window, indirect light 15-34% low).
    inv_reach2: f32,
}

impl CachePoint {
    /// Whether the point answers a lookup at `x` (squared distance `d2`)
    /// on a surface facing `n`: it faces alike and no surface lies between
    /// them ([`in_front`]).
    #[inline]
    fn answers(&self, x: Vec3, n: Vec3, d2: f32) -> bool {
        self.faces(n) & self.in_front_of(x, n, d2)
    }

    /// Whether the point lies on a surface facing like `n`.
    #[inline(always)]
    fn faces(&self, n: Vec3) -> bool {
        normal_times_127(self.normal).dot(n) >= 127.0 * NORMAL_COSINE
    }

    /// Whether no surface lies between the point and `x` (squared distance
    /// `d2`), on a surface facing `n` ([`in_front`]).
    #[inline(always)]
    fn in_front_of(&self, x: Vec3, n: Vec3, d2: f32) -> bool {
        // Both normals 127 times as long, the distance too ([`in_front`]
        // asks for ratios): no division for the stored normal's unit.
        const S: f32 = 127.0;
        in_front(x, S * n, Vec3::from(self.position), normal_times_127(self.normal), S * S * d2)
    }

    fn normal(&self) -> Vec3 {
        normal_times_127(self.normal) / 127.0
    }
}

/// Cells of a uniform grid, hashed: each occupied cell's range of points
/// (sorted by cell). An open-addressing table of 16-byte slots, so that a
/// probe usually costs one cache line (a `HashMap` reads its control bytes
/// and its slots from two places).
struct CellIndex {
    lo: Vec3,
    inv_cell: f32,
    slots: Vec<CellSlot>,
    /// log2 of the slot count.
    bits: u32,
}

/// The range of a query point's cell in the cache's points, if it has one.
#[derive(Clone, Copy, Debug, Default)]
pub struct CellRange(Option<(u32, u32)>);

#[derive(Clone, Copy)]
struct CellSlot {
    key: u64,
    start: u32,
    end: u32,
}

/// Bits per axis of a cell key; coarser cells where a grid would need more.
const CELL_BITS: u32 = 21;
/// Keys use 63 bits, so this one marks an empty slot.
const EMPTY: u64 = u64::MAX;

impl CellIndex {
    fn key(&self, x: Vec3) -> Option<u64> {
        let c = (x - self.lo) * self.inv_cell;
        // Outside the grid (or not finite): no cell. Inside, the cell is
        // the coordinates' floor, which for these non-negative values the
        // cast to an integer takes (f32::floor is a library call here).
        if !(c.min_element() >= 0.0 && c.max_element() < (1u32 << CELL_BITS) as f32) {
            return None;
        }
        Some(c.x as u64 | ((c.y as u64) << CELL_BITS) | ((c.z as u64) << (2 * CELL_BITS)))
    }

    /// The first slot to probe: Fibonacci hashing (one multiply) spreads
    /// the packed coordinates well enough.
    fn home(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.bits)) as usize
    }

    fn insert(&mut self, key: u64, start: u32, end: u32) {
        let mask = self.slots.len() - 1;
        let mut i = self.home(key);
        while self.slots[i].key != EMPTY {
            i = (i + 1) & mask;
        }
        self.slots[i] = CellSlot { key, start, end };
    }

    #[inline]
    fn range(&self, x: Vec3) -> Option<(u32, u32)> {
        if self.slots.is_empty() {
            return None;
        }
        let key = self.key(x)?;
        let mask = self.slots.len() - 1;
        let mut i = self.home(key);
        loop {
            let slot = self.slots[i];
            if slot.key == key {
                return Some((slot.start, slot.end));
            }
            if slot.key == EMPTY {
                return None;
            }
            i = (i + 1) & mask;
        }
    }
}

/// A cache point's squared reach: twice the radius its estimate needed
/// for `k` photons, or, where the radius cap `r_max` stopped it at `count`,
/// would have needed at that density (at most 4 `r_max`). Where the cap
/// stops estimates, the points are sparser than within twice the cap of
/// each other, and a reach of twice the cap left holes between them that
/// the nearest bright points filled (a progressive render's later passes,
/// whose caps are narrower, were the brighter for it).
fn reach2(r2: f32, count: usize, k: usize, r_max: f32) -> f32 {
    let needed = if count >= k || count == 0 { r2 } else { r2 * k as f32 / count as f32 };
    4.0 * needed.min(4.0 * r_max * r_max)
}

/// The irradiance straight from the lights at a cache point: its index
/// and the photon it stands at.
pub type DirectIrradiance<'a> = dyn Fn(u64, &Photon) -> Color + Sync + 'a;

impl IrradianceCache {
    /// Precomputes irradiance at every `stride`-th photon of `map` from its
    /// `k` nearest within `r_max`.
    pub fn build(map: &PhotonMap, stride: usize, k: usize, r_max: f32) -> Self {
        Self::build_with(map, stride, k, r_max, &|_, _, _| 1.0, None)
    }

    /// [`Self::build`], each estimate whose disk holds another surface's
    /// photons divided by `coverage(x, n, r)`: the fraction of the disk of
    /// radius r around x, on the plane of normal n, that lies on x's own
    /// surface (at least a quarter, so that a sliver of surface does not
    /// turn its few photons into a spike); with `direct`, each plus
    /// `direct(i, photon)`, the irradiance straight from the lights at the
    /// `i`-th point, the place of that photon (a map that holds no photon's first hit).
    pub fn build_with(
        map: &PhotonMap,
        stride: usize,
        k: usize,
        r_max: f32,
        coverage: &(dyn Fn(Vec3, Vec3, f32) -> f32 + Sync),
        direct: Option<&DirectIrradiance<'_>>,
    ) -> Self {
        let stride = stride.max(1);
        // Rayon hands each piece of work it splits off a fresh scratch, and
        // with no hint a search starts at the radius cap: ~55,000 photons in
        // the default global map, and at 16 threads thousands of such pieces.
        // They start instead from the radius one estimate needed (the
        // answers do not depend on it).
        let hint = map
            .photons()
            .get(map.len() / 2)
            .map_or(0.0, |p| map.irradiance(p.position(), p.surface_normal(), k, r_max, &mut Scratch::default()).1);
        // Every stride-th photon along the map's spatial order (Morton, or
        // cell by cell): spread evenly over the surfaces.
        let computed: Vec<(CachePoint, f32)> = map
            .spatial_order()
            .step_by(stride)
            .enumerate()
            .map_init(
                || Scratch::with_hint(hint),
                |buf, (i, p)| {
                    let n = p.surface_normal();
                    let est = map.irradiance_estimate(p.position(), n, k, r_max, buf);
                    let (mut e, r2) = (est.irradiance, est.r2);
                    if est.other_surfaces {
                        e /= coverage(p.position(), n, r2.sqrt()).clamp(0.25, 1.0);
                    }
                    if let Some(direct) = direct {
                        e += direct(i as u64, p);
                    }
                    let point = CachePoint {
                        position: p.position().to_array(),
                        irradiance: e.to_array(),
                        normal: quantize_normal(n),
                        inv_reach2: 1.0 / reach2(est.r2, est.count, k, r_max),
                    };
                    (point, r2)
                },
            )
            .collect();
        // Grid cells sized by twice the median estimate radius over the
        // surfaces' area, where lookups fall (each point standing for the
        // area its estimate covers, ~r^2): most lookups find their point in
        // their own cell. The median over the points, as dense as the
        // light, fitted the cells to the brightest surfaces: in a room lit
        // by a sunlit patch, 86% of lookups found their cell empty.
        let mut radii: Vec<f32> = computed.iter().map(|c| c.1).filter(|r2| r2.is_finite()).collect();
        radii.sort_unstable_by(f32::total_cmp);
        let half = radii.iter().map(|&r2| r2 as f64).sum::<f64>() / 2.0;
        let mut covered = 0.0;
        let median_r2 = radii
            .iter()
            .find(|&&r2| {
                covered += r2 as f64;
                covered >= half
            })
            .copied()
            .unwrap_or(0.0);
        let cell_r2 = (4.0 * median_r2).min(r_max * r_max);
        let mut points: Vec<CachePoint> = computed.into_iter().map(|c| c.0).collect();
        let cells = Self::bucket(&mut points, cell_r2.sqrt() * CELL_FRACTION);
        let trees = FacingTrees::build_from(points.len(), |i| (Vec3::from(points[i].position), points[i].normal()));
        let class_reach2 = trees
            .class_items()
            .map(|items| items.iter().map(|&i| 1.0 / points[i as usize].inv_reach2).fold(0.0, f32::max))
            .collect();
        IrradianceCache { points, trees, class_reach2, cells }
    }

    /// Sorts the points by grid cell and indexes each cell's range.
    fn bucket(points: &mut [CachePoint], cell: f32) -> CellIndex {
        let (lo, hi) = bounds(points.iter().map(|p| Vec3::from(p.position)));
        let extent = (hi - lo).max_element();
        let fine_enough = extent / ((1u32 << CELL_BITS) - 2) as f32;
        let cell = if cell.is_finite() && cell > fine_enough { cell } else { fine_enough.max(f32::MIN_POSITIVE) };
        let mut index = CellIndex { lo, inv_cell: 1.0 / cell, slots: Vec::new(), bits: 0 };
        if points.is_empty() || !extent.is_finite() || !index.inv_cell.is_finite() {
            return index;
        }
        // Stable: equal cells keep the points' (spatial) order.
        points.par_sort_by_cached_key(|p| index.key(Vec3::from(p.position)));
        let mut ranges = Vec::new();
        let mut start = 0;
        while start < points.len() {
            let key = index.key(Vec3::from(points[start].position));
            let end = start + points[start..].iter().take_while(|p| index.key(Vec3::from(p.position)) == key).count();
            if let Some(key) = key {
                ranges.push((key, start as u32, end as u32));
            }
            start = end;
        }
        // At most half full: probes stay short.
        index.bits = (2 * ranges.len()).next_power_of_two().trailing_zeros().max(1);
        index.slots = vec![CellSlot { key: EMPTY, start: 0, end: 0 }; 1 << index.bits];
        for (key, start, end) in ranges {
            index.insert(key, start, end);
        }
        index
    }

    /// The points as [`crate::photon::spots`] reads them.
    pub fn spot_points(&self) -> impl Iterator<Item = SpotPoint> + Clone + '_ {
        self.points.iter().map(|p| {
            let (e, n) = (p.irradiance, p.normal);
            SpotPoint {
                position: Vec3::from(p.position),
                normal: Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32).normalize_or_zero(),
                irradiance: (e[0] + e[1] + e[2]) / 3.0,
                // The radius its estimate needed (a quarter of its reach).
                r2: 0.25 / p.inv_reach2,
            }
        })
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Starts fetching the table slot a lookup at `x` will read first.
    #[inline]
    pub fn prefetch_cell(&self, x: Vec3) {
        if let Some(key) = self.cells.key(x).filter(|_| !self.cells.slots.is_empty()) {
            prefetch(&self.cells.slots[self.cells.home(key)]);
        }
    }

    /// Finds `x`'s cell (after [`Self::prefetch_cell`] had time to bring in
    /// its slot) and starts fetching its points, for [`Self::lookup_in`].
    #[inline(always)]
    pub fn locate(&self, x: Vec3) -> CellRange {
        let range = self.cells.range(x);
        if let Some((start, end)) = range {
            prefetch(&self.points[start as usize]);
            prefetch(&self.points[end as usize - 1]);
        }
        CellRange(range)
    }

    /// Irradiance of a cached point near `x`, within that point's reach, on
    /// a surface facing like `n`: of those, the one nearest relative to its
    /// reach (the least d^2 / reach^2), in `x`'s grid cell if it has one,
    /// else anywhere; zero where no photon came near.
    ///
    /// Relative, not plain, distance: cache points are photons, as dense as
    /// the light, so across the edge of a bright patch the dense bright
    /// points are nearer to a point just outside than the sparse dark ones
    /// are, and plain distance let the patch's light spill over a band as
    /// wide as the dark points' spacing: a sunlit patch read by final
    /// gathering was 3-4% too bright, a bias that the progressive passes'
    /// narrowing never removed (each pass's cache is as sparse). Relative
    /// distance puts the border where the two spacings meet.
    pub fn lookup(&self, x: Vec3, n: Vec3) -> Color {
        self.lookup_in(x, n, CellRange(self.cells.range(x)))
    }

    /// [`Self::lookup`] with `x`'s cell already found by [`Self::locate`].
    pub fn lookup_in(&self, x: Vec3, n: Vec3, cell: CellRange) -> Color {
        self.lookup_seen(x, n, cell, |_, _| false)
    }

    /// [`Self::lookup_in`] where a surface may lie between `x` and the
    /// point that answers: a point at another level than `x`'s surface
    /// ([`Self::level_apart`]) answers only where `blocked` (a shadow ray
    /// between the two, lifted off their surfaces) finds nothing between;
    /// else the next nearest answers, up to [`MAX_HIDDEN`] of them hidden.
    /// The plane tests of [`CachePoint::answers`] tell which side of each
    /// other's surface two points lie, but not what lies between at a
    /// grazing angle: from inside a small closed object, the wall beside
    /// it (a lookup reaches up to twice the radius cap).
    ///
    /// Nearly every lookup is answered by the nearest point that faces
    /// alike, which lies in front and at `x`'s level: that point is found
    /// first, as the plain facing test finds it, and the side and level
    /// tests are asked of it alone (the nearest point that answers is the
    /// same wherever it passes them); only where it fails are they asked
    /// of every candidate ([`Self::lookup_hidden`]). Asked of every
    /// candidate, they took the default command's lookups from 11% of its
    /// time to 15% (a profile, 2-core AMD EPYC VM).
    #[inline]
    pub fn lookup_seen(&self, x: Vec3, n: Vec3, cell: CellRange, blocked: impl FnMut(Vec3, Vec3) -> bool) -> Color {
        let Some(i) = self.nearest(x, n, cell, |p, _, _| p.faces(n)) else {
            // None faces alike: none answers.
            return Color::ZERO;
        };
        let p = &self.points[i as usize];
        let d = Vec3::from(p.position) - x;
        let d2 = d.length_squared();
        // The level test's first condition ([`Self::level_apart`]) from the
        // plane distances, with a margin for their rounding.
        let (a, b) = (n.dot(d), normal_times_127(p.normal).dot(d) * (1.0 / 127.0));
        let level = !(a * b > 0.0 && a.abs().min(b.abs()).powi(2) > 0.9 * OFF_PLANE * OFF_PLANE * d2);
        if p.in_front_of(x, n, d2) && (level || self.level_apart(x, n, i).is_none()) {
            return self.irradiance(i);
        }
        self.lookup_hidden(x, n, cell, blocked)
    }

    /// [`Self::lookup_seen`] where the nearest point facing alike lies
    /// behind `x`'s surface or at another level.
    #[cold]
    #[inline(never)]
    fn lookup_hidden(&self, x: Vec3, n: Vec3, cell: CellRange, mut blocked: impl FnMut(Vec3, Vec3) -> bool) -> Color {
        let mut hidden = [u32::MAX; MAX_HIDDEN];
        for h in 0..=MAX_HIDDEN {
            let hidden_now = &hidden[..h];
            let Some(i) = self.nearest(x, n, cell, |p, i, d2| p.answers(x, n, d2) && !hidden_now.contains(&i)) else {
                break;
            };
            match self.level_apart(x, n, i) {
                Some((from, to)) if blocked(from, to) => {
                    if h < MAX_HIDDEN {
                        hidden[h] = i;
                    }
                }
                _ => return self.irradiance(i),
            }
        }
        Color::ZERO
    }

    fn irradiance(&self, i: u32) -> Color {
        Vec3::from(self.points[i as usize].irradiance)
    }

    /// Where cache point `i` lies off the plane of a lookup at `x` (facing
    /// `n`), and `x` off its plane, on the same side of each other's
    /// surface (a > 0 and b > 0 below: it above `x` and `x` behind it, an
    /// overhang; a < 0 and b < 0: it below `x` facing up to it, a step),
    /// both by more than [`OFF_PLANE`] of their distance: the ends of a
    /// ray between them, each lifted off its surface by [`LIFT`] of their
    /// distance. One smooth surface curves the other way (a and b of
    /// opposite signs, equal on a sphere), its points need no ray (and
    /// a straight one between two points of a convex surface would cross
    /// it); points of one plane neither.
    #[inline]
    pub fn level_apart(&self, x: Vec3, n: Vec3, i: u32) -> Option<(Vec3, Vec3)> {
        let point = &self.points[i as usize];
        let (p, m) = (Vec3::from(point.position), point.normal());
        let d = p - x;
        let (a, b) = (n.dot(d), m.dot(d));
        let (off, d2) = (a.abs().min(b.abs()), d.length_squared());
        if !(a * b > 0.0 && off * off > OFF_PLANE * OFF_PLANE * d2) {
            return None;
        }
        // Rounding: points of one plane lie off each other's by about the
        // coordinates' precision.
        let noise = 1e-5 * x.abs().max_element().max(p.abs().max_element()).max(1.0);
        let dist = d2.sqrt();
        if off <= OFF_PLANE * dist + noise {
            return None;
        }
        let lift = LIFT * dist + noise;
        Some((x + lift * n, p + lift * m))
    }

    /// The cache point nearest a lookup at `x` on a surface facing `n`,
    /// relative to its reach ([`Self::lookup`]), of those that `accept`
    /// (the point, its index, its squared distance to `x`); the points
    /// accepted must face like `n`.
    #[inline(always)]
    fn nearest(
        &self,
        x: Vec3,
        n: Vec3,
        cell: CellRange,
        accept: impl Fn(&CachePoint, u32, f32) -> bool,
    ) -> Option<u32> {
        if let Some((start, end)) = cell.0 {
            let mut best: Option<(f32, u32)> = None;
            for (i, p) in (start..end).zip(&self.points[start as usize..end as usize]) {
                let d2 = Vec3::from(p.position).distance_squared(x);
                let q = d2 * p.inv_reach2;
                if q <= 1.0 && best.is_none_or(|b| q < b.0) && accept(p, i, d2) {
                    best = Some((q, i));
                }
            }
            if let Some((_, i)) = best {
                return Some(i);
            }
        }
        // The classes that may face like `n`, and how far any of their
        // points reaches.
        let max_reach2 = self.trees.facing(n).map(|c| self.class_reach2[c]).fold(0.0, f32::max);
        // The wider search grows its radius from a cell's width until a
        // point answers, and on while a point further out could still
        // answer relatively nearer: one whose reach is the largest,
        // `max_reach2`.
        let cell = 1.0 / self.cells.inv_cell;
        let mut r2 = (cell * cell).min(max_reach2);
        loop {
            let mut best: Option<(f32, u32)> = None;
            for c in self.trees.facing(n) {
                self.trees.visit_in(c, x, r2, |i| {
                    let p = &self.points[i as usize];
                    let d2 = Vec3::from(p.position).distance_squared(x);
                    let q = d2 * p.inv_reach2;
                    if q <= 1.0 && best.is_none_or(|b| q < b.0 || (q == b.0 && i < b.1)) && accept(p, i, d2) {
                        best = Some((q, i));
                    }
                });
            }
            // Every point that could beat the best lies within this (q <= 1).
            let enough2 = best.map_or(max_reach2, |(q, _)| q * max_reach2);
            if r2 >= enough2 {
                return best.map(|(_, i)| i);
            }
            r2 = (4.0 * r2).min(enough2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photon::map::tests::uniform_floor;
    use crate::photon::Photon;
    use crate::sampling::{next_2d, stream, Domain};
    use glam::Vec2;
    use rand::RngExt;

    /// A lookup on a surface 0.3 above a lit floor, facing up like it (the
    /// inside of a small closed object standing there): the floor's sparse
    /// points reach it at grazing angles, where no plane test tells that a
    /// surface lies between, so it asks for a ray to each, its ends lifted
    /// off both surfaces; with every ray blocked it reads nothing, with
    /// none what the plain lookup reads. On the floor itself it asks none.
    #[test]
    fn lookups_at_another_level_ask_for_a_ray() {
        let map = PhotonMap::build(uniform_floor(12, 400));
        let cache = IrradianceCache::build(&map, 1, 100, 10.0);
        let mut rng = stream(13, Domain::Camera, 0);
        let (mut asked, mut answered) = (0, 0);
        for _ in 0..100 {
            let u = next_2d(&mut rng) * 4.0;
            let (x, floor) = (Vec3::new(u.x, 0.3, u.y), Vec3::new(u.x, 0.0, u.y));
            let cell = cache.locate(x);
            let plain = cache.lookup_in(x, Vec3::Y, cell);
            answered += (plain != Color::ZERO) as usize;
            let mut rays = 0;
            let hidden = cache.lookup_seen(x, Vec3::Y, cell, |from, to| {
                rays += 1;
                assert!(from.y > 0.3 && to.y > 0.0 && to.y < 0.3, "{from} to {to}");
                true
            });
            assert_eq!(hidden, Color::ZERO, "at {x}");
            assert!(plain == Color::ZERO || (1..=MAX_HIDDEN + 1).contains(&rays), "{rays} rays at {x}");
            asked += rays;
            assert_eq!(cache.lookup_seen(x, Vec3::Y, cell, |_, _| false), plain, "at {x}");
            let on_floor = cache.lookup_seen(floor, Vec3::Y, cache.locate(floor), |_, _| panic!("a ray on the floor"));
            assert_eq!(on_floor, cache.lookup(floor, Vec3::Y));
        }
        // Most lookups found a point: the case is real, and each asked.
        assert!(answered > 50 && asked >= answered, "{answered} answered, {asked} rays");
    }

    /// Cache points on the outside of a unit sphere answer no lookup from
    /// its inside, however far they reach; from the outside they answer
    /// with the photons' density.
    #[test]
    fn lookups_do_not_read_through_a_closed_surface() {
        let map = PhotonMap::build(crate::photon::map::tests::sphere_outside(10, 40_000));
        let cache = IrradianceCache::build(&map, 8, 100, 3.0);
        let mut rng = stream(11, Domain::Camera, 0);
        let mut outside = 0.0;
        for _ in 0..200 {
            let d = crate::sampling::uniform_cone(next_2d(&mut rng), -1.0).normalize();
            assert_eq!(cache.lookup(d, -d), Color::ZERO, "at {d}");
            assert_eq!(cache.lookup(0.5 * d, -d), Color::ZERO, "at {}", 0.5 * d);
            outside += cache.lookup(d, d).x as f64;
        }
        let mean = outside / 200.0 * 4.0 * std::f64::consts::PI;
        assert!((mean - 1.0).abs() < 0.05, "outside: {mean} of the density");
    }

    /// A map without a tree (nor a Morton order) picks its cache points
    /// along its grid's cells: still spread evenly, so that lookups all over
    /// the surface find a point near them and the irradiance there.
    #[test]
    fn a_grid_only_map_spreads_its_cache_points() {
        let photons = uniform_floor(21, 100_000);
        let map = PhotonMap::build_for_photon_lookups(photons, 0.1);
        assert!(map.grid.is_some() && map.tree.is_none() && map.tree_place.is_none());
        let cache = IrradianceCache::build(&map, 4, 100, 1.0);
        assert_eq!(cache.len(), 25_000);
        let mut buf = Scratch::default();
        for i in 0..10 {
            for j in 0..10 {
                let x = Vec3::new(0.2 + 0.4 * i as f32, 0.0, 0.2 + 0.4 * j as f32);
                let cached = cache.lookup(x, Vec3::Y).x;
                let direct = map.irradiance(x, Vec3::Y, 100, 1.0, &mut buf).0.x;
                assert!((cached / direct - 1.0).abs() < 0.3, "at {x}: {cached} vs {direct}");
            }
        }
    }

    /// A bright patch on a dark floor (50 times the irradiance, equal-power
    /// photons): the light final gathering reads through the cache, summed
    /// over the floor, is the light the direct estimates give, although the
    /// cache's points are as dense as the photons: a plain nearest point
    /// spread the patch over the dark side (+6% at every 16th photon). Also
    /// where the radius cap stops the dark side's estimates, as in a
    /// progressive render's later passes: a reach of twice the cap left
    /// holes that the bright points filled (+4%).
    #[test]
    fn a_bright_patch_read_through_the_cache_keeps_its_light() {
        let mut rng = stream(3, Domain::Camera, 0);
        let (n, contrast) = (100_000, 50.0);
        // The patch is [1, 2]^2 on the floor [0, 4]^2.
        let in_patch = contrast / (contrast + 15.0);
        let photons: Vec<Photon> = (0..n)
            .map(|_| {
                let p = if rng.random::<f32>() < in_patch {
                    Vec2::ONE + next_2d(&mut rng)
                } else {
                    loop {
                        let v = next_2d(&mut rng) * 4.0;
                        if !(v.cmpge(Vec2::ONE).all() && v.cmplt(Vec2::splat(2.0)).all()) {
                            break v;
                        }
                    }
                };
                Photon::new(Vec3::new(p.x, 0.0, p.y), Color::splat(1.0 / n as f32), Vec3::Y)
            })
            .collect();
        let map = PhotonMap::build_for_photon_lookups(photons, 0.05);
        // Uncapped (the dark side's estimates need ~0.18), and capped.
        for (r_max, tolerance) in [(1.0, 0.015), (0.05, 0.03)] {
            let cache = IrradianceCache::build(&map, 16, 100, r_max);
            let mut buf = Scratch::default();
            let m = 300;
            let (mut cached, mut direct) = (0.0f64, 0.0f64);
            // Around the patch, clear of the floor's own edges.
            for i in 0..m {
                for j in 0..m {
                    let u = (Vec2::new(i as f32, j as f32) + 0.5) / m as f32;
                    let x = Vec3::new(0.5 + 2.0 * u.x, 0.0, 0.5 + 2.0 * u.y);
                    cached += cache.lookup(x, Vec3::Y).x as f64;
                    direct += map.irradiance(x, Vec3::Y, 100, r_max, &mut buf).0.x as f64;
                }
            }
            let ratio = cached / direct;
            assert!((ratio - 1.0).abs() < tolerance, "cap {r_max}: cache / direct = {ratio}");
        }
    }

    /// A map sorted by the grid's cells computes its cache at the same
    /// photons (every stride-th along the Morton order) and finds the same
    /// irradiance there (its sums run in another order: last bits only).
    #[test]
    fn irradiance_cache_is_the_same_with_a_grid() {
        let mut rng = stream(18, Domain::Camera, 0);
        let photons: Vec<Photon> = (0..50_000)
            .map(|i| {
                let u = next_2d(&mut rng) * 4.0;
                match i % 2 {
                    0 => Photon::new(Vec3::new(u.x, 0.0, u.y), Color::ONE, Vec3::Y),
                    _ => Photon::new(Vec3::new(0.0, u.x, u.y), Color::splat(0.5), Vec3::X),
                }
            })
            .collect();
        let plain = IrradianceCache::build(&PhotonMap::build(photons.clone()), 4, 50, 1.0);
        let gridded_map = PhotonMap::build_with_grid(photons, Some(0.05));
        assert!(gridded_map.grid.is_some());
        let gridded = IrradianceCache::build(&gridded_map, 4, 50, 1.0);
        let key = |c: &CachePoint| c.position.map(f32::to_bits);
        let (mut a, mut b) = (plain.points.clone(), gridded.points.clone());
        a.sort_by_key(key);
        b.sort_by_key(key);
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(&b) {
            assert_eq!(p.position, q.position);
            for c in 0..3 {
                let (x, y) = (p.irradiance[c], q.irradiance[c]);
                assert!((x - y).abs() <= 1e-5 * x.abs().max(1e-30), "{x} vs {y}");
            }
        }
    }

    #[test]
    fn irradiance_cache_agrees_with_direct_estimate() {
        let photons = uniform_floor(12, 100_000);
        let map = PhotonMap::build(photons);
        let cache = IrradianceCache::build(&map, 4, 100, 1.0);
        assert_eq!(cache.len(), 25_000);
        let x = Vec3::new(2.0, 0.0, 2.0);
        let direct = map.irradiance(x, Vec3::Y, 100, 1.0, &mut Scratch::default()).0.x;
        let cached = cache.lookup(x, Vec3::Y).x;
        assert!((cached / direct - 1.0).abs() < 0.25, "{cached} {direct}");
        assert!((direct / 6250.0 - 1.0).abs() < 0.2, "{direct}");
        assert_eq!(cache.lookup(x, -Vec3::Y), Color::ZERO);
    }

    /// In a corner a lookup's grid cell holds points of both surfaces: each
    /// query gets its own surface's irradiance, from its cell or, where the
    /// cell holds only the other surface's points, from the tree. Every
    /// answer is the irradiance of a point that faces the query and lies
    /// within the lookup radius.
    #[test]
    fn irradiance_cache_keeps_surfaces_apart_in_a_corner() {
        let mut rng = stream(13, Domain::Camera, 0);
        // Floor y = 0 (power 1) and wall x = 0 (power 3), 4 x 4 each.
        let photons: Vec<Photon> = (0..100_000)
            .map(|i| {
                let u = next_2d(&mut rng) * 4.0;
                if i % 2 == 0 {
                    Photon::new(Vec3::new(u.x, 0.0, u.y), Color::ONE, Vec3::Y)
                } else {
                    Photon::new(Vec3::new(0.0, u.x, u.y), Color::splat(3.0), Vec3::X)
                }
            })
            .collect();
        let map = PhotonMap::build(photons);
        let cache = IrradianceCache::build(&map, 4, 100, 1.0);
        let (floor, wall) = (50_000.0 / 16.0, 3.0 * 50_000.0 / 16.0);
        for i in 0..200 {
            let d = 1e-3 + 0.4 * i as f32 / 200.0;
            let z = 0.5 + 3.0 * (i % 17) as f32 / 17.0;
            let on_floor = cache.lookup(Vec3::new(d, 0.0, z), Vec3::Y).x;
            let on_wall = cache.lookup(Vec3::new(0.0, d, z), Vec3::X).x;
            // Near the corner the estimates themselves lose up to half
            // their disk; far from the other surface is all that is asked.
            assert!(on_floor > 0.3 * floor && on_floor < 1.3 * floor, "floor at {d}: {on_floor}");
            assert!(on_wall > 0.3 * wall && on_wall < 1.3 * wall, "wall at {d}: {on_wall}");
        }
        // Points facing the other way exist nowhere: nothing is returned.
        assert_eq!(cache.lookup(Vec3::new(0.2, 0.0, 2.0), -Vec3::Y), Color::ZERO);
        // Outside the grid and far from every point: zero, not a far value.
        assert_eq!(cache.lookup(Vec3::new(50.0, 50.0, 50.0), Vec3::Y), Color::ZERO);
        assert_eq!(cache.lookup(Vec3::splat(f32::NAN), Vec3::Y), Color::ZERO);
        // A cache over no photons answers zero everywhere.
        let empty = IrradianceCache::build(&PhotonMap::build(Vec::new()), 4, 100, 1.0);
        assert_eq!(empty.lookup(Vec3::new(0.2, 0.0, 2.0), Vec3::Y), Color::ZERO);
    }

    /// A thin wall, densely lit on one side and dimly on the other, meeting
    /// a floor: lookups on either side, most of the dim side's falling
    /// through their cell to the facing trees, give what a search of every
    /// point gives (the best facing point within reach, relative distance,
    /// in the cell where it holds one).
    #[test]
    fn the_facing_trees_answer_as_a_search_of_every_point() {
        let mut rng = stream(17, Domain::Camera, 0);
        let mut photons = Vec::new();
        for i in 0..120_000 {
            let u = next_2d(&mut rng) * 2.0;
            let (pos, n, power) = match i % 60 {
                0 => (Vec3::new(u.x, 0.0, u.y), -Vec3::Y, 1.0),
                1..=9 => (Vec3::new(u.x, u.y, 0.0), Vec3::Z, 2.0),
                _ => (Vec3::new(u.x * 0.5, 0.0, u.y * 0.5), Vec3::Y, 5.0),
            };
            photons.push(Photon::new(pos, Color::splat(power), n));
        }
        let map = PhotonMap::build(photons);
        let cache = IrradianceCache::build(&map, 4, 50, 1.0);
        let plain = |x: Vec3, n: Vec3| {
            let best_of = |points: &[CachePoint]| {
                let mut best: Option<(f32, usize)> = None;
                for (i, p) in points.iter().enumerate() {
                    let d2 = Vec3::from(p.position).distance_squared(x);
                    let q = d2 * p.inv_reach2;
                    if q <= 1.0 && p.answers(x, n, d2) && best.is_none_or(|b| q < b.0) {
                        best = Some((q, i));
                    }
                }
                best.map(|(_, i)| Vec3::from(points[i].irradiance))
            };
            let in_cell = cache.cells.range(x).and_then(|(a, b)| best_of(&cache.points[a as usize..b as usize]));
            (in_cell.is_none(), in_cell.or_else(|| best_of(&cache.points)).unwrap_or(Color::ZERO))
        };
        let mut fell_through = 0;
        for _ in 0..3000 {
            let u = next_2d(&mut rng) * 2.2;
            for (x, n) in [
                (Vec3::new(u.x, 0.0, u.y), -Vec3::Y),
                (Vec3::new(u.x, 0.0, u.y), Vec3::Y),
                (Vec3::new(u.x, u.y, 0.0), Vec3::Z),
            ] {
                let (through, expected) = plain(x, n);
                fell_through += through as u32;
                assert_eq!(cache.lookup(x, n), expected, "at {x} facing {n}");
            }
        }
        assert!(fell_through > 1000, "{fell_through}");
    }
}
