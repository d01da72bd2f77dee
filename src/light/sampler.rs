//! Choosing a light for a shadow ray among many: a light hierarchy.
//!
//! A binary tree over the lights that have a place (area, point, spot,
//! projector), each node bounding its lights' box, total power and the
//! cone of directions they emit into; a shadow ray at a point descends it,
//! choosing each child in proportion to an importance that bounds what the
//! child's lights can send there (their power over the distance squared,
//! times the cosine of the smallest angle between their emission and the
//! point, and of that between the point's normal and them). This is the
//! light BVH of Conty Estévez and Kulla ("Importance sampling of many
//! lights with adaptive tree splitting", 2018) in the form pbrt-v4 gives
//! it (Pharr, Jakob, Humphreys, *pbrt*, 4th ed., §12.6.3: its importance,
//! the union of direction cones of §3.8.4, and the build's cost with the
//! orientation measure M_Ω). Lights at infinity (directional, sky,
//! environment map) have no place: each is chosen uniformly among them and
//! the tree, as one.
//!
//! The importance is conservative: a light that can send anything to a
//! point has a positive chance there, so the estimate stays unbiased; a
//! cluster that cannot (behind a one-sided light, outside a spot's cone)
//! is never chosen. The probability of a light is the product of the
//! choices down to it, recomputed from the leaf up for multiple importance
//! sampling.

use super::Light;
use super::LightBounds;
use glam::{Vec3, Vec4};

/// Lights drawn from the hierarchy for an estimate that would take
/// `count` shadow rays per light among a few: `count` clamped to 4..=8.
/// Where a few lights are each visited `--shadow-rays` (2) times, two
/// draws of many were noisier at equal time than four; the irradiance
/// cache's 16 per light cost twice 8 draws and changed no image's error
/// (examples/many_lights.rs, notes/performance.md).
pub fn draws(count: u32) -> u32 {
    count.clamp(4, 8)
}

// The importance is the tree's own node test applied to one cluster.
impl LightBounds {
    /// What the lights bounded can send to a point `p` on a surface facing
    /// `n` (zero `n`: not on a surface); zero only where they send nothing.
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let mut node = Node::default();
        node.set(0, self, 0);
        node.importance(p, n)[0]
    }
}

/// A node of the tree: four children side by side, lane by lane (the
/// bounding sphere, the power, the cone's axis, the cosines and sine of θo
/// and θe), so that one pass of four-wide arithmetic weighs all four and a
/// descent through 100,000 lights takes about nine steps. A child is a node
/// or, with [`LEAF`] set, a light; an unused lane has no power.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
struct Node {
    cx: Vec4,
    cy: Vec4,
    cz: Vec4,
    /// The bounding sphere's radius.
    r: Vec4,
    wx: Vec4,
    wy: Vec4,
    wz: Vec4,
    phi: Vec4,
    cos_o: Vec4,
    sin_o: Vec4,
    cos_e: Vec4,
    child: [u32; 4],
}

/// A child that is a light.
const LEAF: u32 = 1 << 31;

impl Node {
    /// Lane `k` bounds `b`.
    fn set(&mut self, k: usize, b: &LightBounds, child: u32) {
        let center = (b.lo + b.hi) * 0.5;
        // The radius rounds up: the sphere holds the box.
        let r = (b.hi - b.lo).length() * 0.5 * (1.0 + 1e-6);
        let sin_o = (1.0 - b.cos_o * b.cos_o).max(0.0).sqrt();
        for (lane, v) in [
            (&mut self.cx, center.x),
            (&mut self.cy, center.y),
            (&mut self.cz, center.z),
            (&mut self.r, r),
            (&mut self.wx, b.w.x),
            (&mut self.wy, b.w.y),
            (&mut self.wz, b.w.z),
            (&mut self.phi, b.phi),
            (&mut self.cos_o, b.cos_o),
            (&mut self.sin_o, sin_o),
            (&mut self.cos_e, b.cos_e),
        ] {
            lane[k] = v;
        }
        self.child[k] = child;
    }

    /// The four children's importance at `p` (facing `n`), as
    /// pbrt-v4's LightBounds::Importance: a cluster's power over the
    /// distance squared (at least its radius squared), times the cosine of
    /// the smallest angle between a direction it emits along and one from
    /// it to `p` (θw - θo - θb, zero beyond θe more), times that of the
    /// smallest angle between the normal (either side) and a direction to
    /// it (θi - θb).
    #[inline]
    fn importance(&self, p: Vec3, n: Vec3) -> Vec4 {
        let (tx, ty, tz) = (Vec4::splat(p.x) - self.cx, Vec4::splat(p.y) - self.cy, Vec4::splat(p.z) - self.cz);
        let dist2 = tx * tx + ty * ty + tz * tz;
        let r2 = self.r * self.r;
        let outside = dist2.cmpgt(r2);
        // 1 / distance, and 1 / the squared distance clamped to the
        // sphere's radius from below.
        let inv = dist2.sqrt().recip();
        let inv_d2 = Vec4::select(outside, inv * inv, r2.recip());
        let wix = Vec4::select(outside, tx * inv, self.wx);
        let wiy = Vec4::select(outside, ty * inv, self.wy);
        let wiz = Vec4::select(outside, tz * inv, self.wz);
        let sin_b = Vec4::select(outside, (self.r * inv).min(Vec4::ONE), Vec4::ZERO);
        let cos_b = Vec4::select(outside, (Vec4::ONE - sin_b * sin_b).max(Vec4::ZERO).sqrt(), Vec4::NEG_ONE);
        let cos_w = (self.wx * wix + self.wy * wiy + self.wz * wiz).clamp(Vec4::NEG_ONE, Vec4::ONE);
        let sin_w = (Vec4::ONE - cos_w * cos_w).max(Vec4::ZERO).sqrt();
        let within = cos_w.cmpgt(self.cos_o);
        let cos_x = Vec4::select(within, Vec4::ONE, cos_w * self.cos_o + sin_w * self.sin_o);
        let sin_x = Vec4::select(within, Vec4::ZERO, sin_w * self.cos_o - cos_w * self.sin_o);
        let cos_p = Vec4::select(cos_x.cmpgt(cos_b), Vec4::ONE, cos_x * cos_b + sin_x * sin_b);
        let mut importance = self.phi * cos_p.max(Vec4::ZERO) * inv_d2;
        if n != Vec3::ZERO {
            let cos_i = (wix * n.x + wiy * n.y + wiz * n.z).abs().min(Vec4::ONE);
            let sin_i = (Vec4::ONE - cos_i * cos_i).max(Vec4::ZERO).sqrt();
            importance *= Vec4::select(cos_i.cmpgt(cos_b), Vec4::ONE, cos_i * cos_b + sin_i * sin_b);
        }
        // Nothing where the cone misses the point or the lane is unused;
        // overflow counts as the largest importance.
        let none = cos_p.cmplt(self.cos_e) | self.phi.cmple(Vec4::ZERO) | !importance.cmpge(Vec4::ZERO);
        Vec4::select(none, Vec4::ZERO, importance.min(Vec4::splat(f32::MAX)))
    }
}

/// Deeper than this, a cluster is split at its median: no chain of
/// lopsided splits can grow the tree (and the build's recursion) with the
/// number of lights (at most 48 + 32 levels).
const MAX_SAH_DEPTH: u32 = 48;
/// Buckets per axis the build's cost is evaluated at.
const BUCKETS: usize = 12;

/// The binary tree the build makes before its levels are taken two at a
/// time into four-wide nodes.
struct Binary {
    bounds: LightBounds,
    /// Two children, or where a leaf's lights start (in [`Clusters`]).
    kids: Result<[usize; 2], u32>,
}

/// The lights of the tree's leaves: a leaf holds one light, or up to
/// [`CLUSTER`] lights close together and facing alike (neighbouring
/// triangles of a mesh), chosen among them by power. A leaf names the
/// first of its lights; each light is stored with the running share of
/// its leaf's power up to and with it (the last 1), so that the choice
/// reads one run of memory.
#[derive(Clone, Debug, Default)]
struct Clusters {
    entries: Vec<(u32, f32)>,
}

/// The most lights a leaf holds.
const CLUSTER: usize = 16;
/// A leaf of several lights spans at most this share of the scene's
/// diagonal, and their normals lie within 15 degrees of its axis: points
/// beyond a few times that distance see them alike (nearer ones are
/// still sampled without bias, by power within the leaf).
const CLUSTER_SPAN: f32 = 0.005;
const CLUSTER_COS: f32 = 0.966;

impl Clusters {
    /// A leaf of `items`; returns where its lights start.
    fn push(&mut self, items: &[(u32, LightBounds)]) -> u32 {
        let start = self.entries.len() as u32;
        let total: f64 = items.iter().map(|(_, b)| b.phi as f64).sum();
        let mut running = 0.0;
        for (light, b) in items {
            running += b.phi as f64;
            self.entries.push((*light, (running / total) as f32));
        }
        if let Some(last) = self.entries.last_mut() {
            last.1 = 1.0;
        }
        start
    }

    /// The light of the leaf starting at `start` chosen by `u` in [0, 1),
    /// and its share.
    #[inline]
    fn choose(&self, start: u32, u: f32) -> (u32, f32) {
        let mut below = 0.0;
        let mut at = start as usize;
        // The last running share is 1: the scan ends in the leaf.
        while let Some(&(light, running)) = self.entries.get(at) {
            if u < running || running >= 1.0 {
                return (light, running - below);
            }
            below = running;
            at += 1;
        }
        (self.entries[start as usize].0, 0.0)
    }

    /// The share of entry `at` in its leaf starting at `start`.
    #[inline]
    fn share(&self, at: usize, start: usize) -> f32 {
        self.entries[at].1 - if at > start { self.entries[at - 1].1 } else { 0.0 }
    }
}

/// Where a light or a node sits: its node and lane.
#[derive(Clone, Copy, Debug)]
struct Slot {
    node: u32,
    lane: u8,
}

/// The light hierarchy of a scene's lights.
#[derive(Clone, Debug)]
pub struct LightSampler {
    /// The root is node 0.
    nodes: Vec<Node>,
    /// Per node, where it sits in its parent (the root: nowhere).
    parent: Vec<Option<Slot>>,
    /// Per light of the scene: its leaf's lane and its place in the
    /// cluster's lights (`None`: not in the tree).
    leaf_of: Vec<Option<(Slot, u32)>>,
    clusters: Clusters,
    /// The lights without a place, chosen uniformly with the tree.
    infinite: Vec<u32>,
    /// Whether the tree holds any light.
    any: bool,
}

impl LightSampler {
    /// The hierarchy of `lights` in a scene of box diagonal `diagonal`.
    pub fn new(lights: &[Light], diagonal: f32) -> Self {
        let mut items = Vec::new();
        let mut infinite = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            match l.light_bounds() {
                Some(b) if b.phi > 0.0 => items.push((i as u32, b)),
                Some(_) => {}
                None => infinite.push(i as u32),
            }
        }
        let mut tree = LightSampler {
            nodes: Vec::new(),
            parent: Vec::new(),
            leaf_of: vec![None; lights.len()],
            clusters: Clusters::default(),
            infinite,
            any: !items.is_empty(),
        };
        if items.is_empty() {
            return tree;
        }
        let mut binary = Vec::with_capacity(2 * items.len());
        let span = diagonal * CLUSTER_SPAN;
        let root = build_binary(&mut items, &mut binary, &mut tree.clusters, span, 0);
        tree.nodes.push(Node::default());
        tree.parent.push(None);
        let children = match binary[root].kids {
            Ok(kids) => kids.to_vec(),
            Err(_) => vec![root],
        };
        tree.fill(0, children, &binary);
        tree
    }

    /// Makes node `at` of the binary subtrees `children` (at most two),
    /// opening the inner ones of most power until four lanes are full.
    fn fill(&mut self, at: u32, mut children: Vec<usize>, binary: &[Binary]) {
        while children.len() < 4 {
            let open = children
                .iter()
                .enumerate()
                .filter(|(_, &c)| binary[c].kids.is_ok())
                .max_by(|a, b| binary[*a.1].bounds.phi.total_cmp(&binary[*b.1].bounds.phi))
                .map(|(k, _)| k);
            let Some(k) = open else { break };
            let Ok([a, b]) = binary[children[k]].kids else { break };
            children[k] = a;
            children.push(b);
        }
        let mut node = Node::default();
        let mut inner = Vec::new();
        for (lane, &c) in children.iter().enumerate() {
            let slot = Slot { node: at, lane: lane as u8 };
            match binary[c].kids {
                Err(start) => {
                    node.set(lane, &binary[c].bounds, LEAF | start);
                    for at in start as usize.. {
                        let (light, running) = self.clusters.entries[at];
                        self.leaf_of[light as usize] = Some((slot, at as u32));
                        if running >= 1.0 {
                            break;
                        }
                    }
                }
                Ok(kids) => {
                    let index = self.nodes.len() as u32;
                    self.nodes.push(Node::default());
                    self.parent.push(Some(slot));
                    node.set(lane, &binary[c].bounds, index);
                    inner.push((index, kids));
                }
            }
        }
        self.nodes[at as usize] = node;
        for (index, kids) in inner {
            self.fill(index, kids.to_vec(), binary);
        }
    }

    /// The chance of choosing the tree rather than a light at infinity.
    #[inline]
    fn tree_share(&self) -> f32 {
        let tree = self.any as usize;
        tree as f32 / (self.infinite.len() + tree) as f32
    }

    /// A light for a shadow ray at `p` on a surface facing `n` (zero: not
    /// on a surface), chosen by `u` in [0, 1), with the chance of that
    /// choice; `None` where no light can send anything there.
    pub fn sample(&self, p: Vec3, n: Vec3, u: f64) -> Option<(usize, f32)> {
        let tree_share = self.tree_share();
        let infinite_share = 1.0 - tree_share as f64;
        if u < infinite_share {
            let k = ((u / infinite_share * self.infinite.len() as f64) as usize).min(self.infinite.len() - 1);
            return Some((self.infinite[k] as usize, (infinite_share / self.infinite.len() as f64) as f32));
        }
        // `u` falls in the interval [lo, lo + width) of the node reached;
        // each step keeps the child's part of it (no division by the
        // chances along the descent).
        let (mut lo, mut width) = (infinite_share, 1.0 - infinite_share);
        let mut pmf = tree_share;
        let mut node = &self.nodes[0];
        loop {
            let weights = node.importance(p, n);
            let total = weights.element_sum();
            if !(total > 0.0) {
                return None;
            }
            // The lane whose part of the interval holds `u`; a lane of no
            // chance is never taken, whatever the rounding.
            let (mut lane, mut below, mut last, mut found) = (0, 0.0f64, 0.0f64, false);
            for k in 0..4 {
                if weights[k] > 0.0 {
                    lane = k;
                    last = width * (weights[k] / total) as f64;
                    if u < lo + below + last {
                        found = true;
                        break;
                    }
                    below += last;
                }
            }
            if !found {
                // Past every part by rounding: the last lane of any chance.
                below -= last;
            }
            let share = weights[lane] / total;
            (lo, width) = (lo + below, width * share as f64);
            pmf *= share;
            let child = node.child[lane];
            if child & LEAF != 0 {
                // The rest of `u`'s place in the lane's interval chooses
                // within the cluster.
                let v = (((u - lo) / width) as f32).clamp(0.0, 1.0 - f32::EPSILON);
                let (light, share) = self.clusters.choose(child & !LEAF, v);
                return Some((light as usize, pmf * share));
            }
            node = &self.nodes[child as usize];
        }
    }

    /// The chance [`Self::sample`] at `p`, `n` chooses light `index`.
    pub fn pmf(&self, p: Vec3, n: Vec3, index: usize) -> f32 {
        let tree_share = self.tree_share();
        let Some((mut slot, at)) = self.leaf_of.get(index).copied().flatten() else {
            return if self.infinite.contains(&(index as u32)) {
                ((1.0 - tree_share as f64) / self.infinite.len() as f64) as f32
            } else {
                0.0
            };
        };
        let start = self.nodes[slot.node as usize].child[slot.lane as usize] & !LEAF;
        let in_cluster = self.clusters.share(at as usize, start as usize);
        // The same products as the descent, from the leaf up.
        let mut shares = [0f32; 128];
        let mut depth = 0;
        loop {
            let weights = self.nodes[slot.node as usize].importance(p, n);
            let share = weights[slot.lane as usize] / weights.element_sum();
            if !(share > 0.0) {
                return 0.0;
            }
            if depth < shares.len() {
                shares[depth] = share;
            }
            depth += 1;
            match self.parent[slot.node as usize] {
                Some(up) => slot = up,
                None => break,
            }
        }
        shares[..depth.min(shares.len())].iter().rev().fold(tree_share, |pmf, s| pmf * s) * in_cluster
    }

    /// Bytes the tree holds.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.parent.capacity() * std::mem::size_of::<Option<Slot>>()
            + self.leaf_of.capacity() * std::mem::size_of::<Option<(Slot, u32)>>()
            + self.clusters.entries.capacity() * 8
            + self.infinite.capacity() * 4
    }
}

/// Builds the binary tree of `items` into `nodes`, its leaves' lights
/// into `clusters` (several lights together where they span at most
/// `span` and face alike); returns its root.
fn build_binary(
    items: &mut [(u32, LightBounds)],
    nodes: &mut Vec<Binary>,
    clusters: &mut Clusters,
    span: f32,
    depth: u32,
) -> usize {
    let bounds = items[1..].iter().fold(items[0].1, |b, (_, x)| b.union(x));
    let together = items.len() <= CLUSTER && (bounds.hi - bounds.lo).length() <= span && bounds.cos_o >= CLUSTER_COS;
    if items.len() == 1 || together {
        nodes.push(Binary { bounds, kids: Err(clusters.push(items)) });
        return nodes.len() - 1;
    }
    let mid = split(items, &bounds, depth);
    let (left, right) = items.split_at_mut(mid);
    let a = build_binary(left, nodes, clusters, span, depth + 1);
    let b = build_binary(right, nodes, clusters, span, depth + 1);
    nodes.push(Binary { bounds, kids: Ok([a, b]) });
    nodes.len() - 1
}

/// Orders `items` into two clusters of the least cost (pbrt-v4's
/// surface-area-orientation heuristic over buckets of the centroids along
/// each axis), and returns where the second starts; at the median of the
/// widest axis below [`MAX_SAH_DEPTH`] or where no bucket split exists.
fn split(items: &mut [(u32, LightBounds)], bounds: &LightBounds, depth: u32) -> usize {
    let centroid = |b: &LightBounds| (b.lo + b.hi) * 0.5;
    let (mut clo, mut chi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (_, b) in items.iter() {
        clo = clo.min(centroid(b));
        chi = chi.max(centroid(b));
    }
    let extent = chi - clo;
    let widest = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let median = |items: &mut [(u32, LightBounds)], axis: usize| {
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| centroid(&a.1)[axis].total_cmp(&centroid(&b.1)[axis]));
        mid
    };
    if depth >= MAX_SAH_DEPTH || !(extent.max_element() > 0.0) {
        return median(items, widest);
    }
    let diag = bounds.hi - bounds.lo;
    // The buckets are filled from at most 4096 of the lights, evenly
    // strided: the cost of a split is judged as well, and a level of a
    // large tree costs its partition, not 3 x n unions.
    let stride = items.len().div_ceil(4096);
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if !(extent[axis] > 0.0) {
            continue;
        }
        let bucket = |b: &LightBounds| {
            let t = (centroid(b)[axis] - clo[axis]) / extent[axis];
            ((t * BUCKETS as f32) as usize).min(BUCKETS - 1)
        };
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for (_, b) in items.iter().step_by(stride) {
            let k = bucket(b);
            buckets[k] = Some(buckets[k].map_or(*b, |x| x.union(b)));
        }
        let thinness = diag.max_element() / diag[axis].max(f32::MIN_POSITIVE);
        // The clusters below and above each cut, by one sweep each way.
        let join = |acc: Option<LightBounds>, k: usize| match (acc, buckets[k]) {
            (Some(a), Some(b)) => Some(a.union(&b)),
            (a, b) => a.or(b),
        };
        let mut below = [None; BUCKETS];
        let mut above = [None; BUCKETS];
        for k in 1..BUCKETS {
            below[k] = join(below[k - 1], k - 1);
            above[BUCKETS - 1 - k] = join(above[BUCKETS - k], BUCKETS - k);
        }
        for cut in 1..BUCKETS {
            let (Some(l), Some(r)) = (below[cut], join(above[cut], cut)) else { continue };
            let cost = l.cost(thinness) + r.cost(thinness);
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, cut));
            }
        }
    }
    let Some((_, axis, cut)) = best else { return median(items, widest) };
    let below = |b: &LightBounds| {
        let t = (centroid(b)[axis] - clo[axis]) / extent[axis];
        (((t * BUCKETS as f32) as usize).min(BUCKETS - 1)) < cut
    };
    let mut mid = 0;
    for i in 0..items.len() {
        if below(&items[i].1) {
            items.swap(i, mid);
            mid += 1;
        }
    }
    if mid == 0 || mid == items.len() {
        median(items, widest)
    } else {
        mid
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{AreaLight, Emitting, PointLight};
    use crate::math::Color;
    use crate::sampling::{next_2d, stream, uniform_cone, Domain};
    use crate::shape::Disk;

    fn disks(n: usize) -> Vec<Light> {
        let mut rng = stream(3, Domain::Camera, 0);
        (0..n)
            .map(|i| {
                let u = next_2d(&mut rng);
                let center = Vec3::new(u.x * 10.0, u.y * 10.0, (i % 3) as f32);
                let normal = uniform_cone(next_2d(&mut rng), -1.0).normalize();
                let disk = Disk { center, normal, radius: 0.05 + 0.1 * u.x };
                Light::Area(AreaLight::new(Emitting::Disk(disk), Color::splat(1.0 + (i % 4) as f32), i as u32))
            })
            .collect()
    }

    /// The chances of every light at a point sum to at most one (a
    /// descent can end at a light that sends nothing there: no light is
    /// chosen), and each is the one the descent gives it (the frequency of
    /// its choice), as is the chance of none.
    #[test]
    fn the_chances_sum_to_one_and_are_those_of_the_descent() {
        let mut lights = disks(300);
        lights.push(Light::Point(PointLight {
            position: Vec3::new(5.0, 5.0, 5.0),
            intensity: Color::ONE,
            falloff: 2.0,
            dead_distance: 0.0,
        }));
        lights.push(Light::Constant(crate::light::Constant::new(Color::ONE)));
        let tree = LightSampler::new(&lights, 20.0);
        let mut rng = stream(4, Domain::Camera, 1);
        for (p, n) in [
            (Vec3::new(3.0, 4.0, 1.5), Vec3::Z),
            (Vec3::new(-2.0, 5.0, 0.0), Vec3::X),
            (Vec3::new(5.0, 5.0, 1.0), Vec3::ZERO),
        ] {
            let total: f64 = (0..lights.len()).map(|i| tree.pmf(p, n, i) as f64).sum();
            assert!(total <= 1.0 + 1e-4 && total > 0.5, "{p}: {total}");
            let draws = 200_000;
            let mut count = vec![0u32; lights.len() + 1];
            for _ in 0..draws {
                let u = rand::RngExt::random::<f64>(&mut rng);
                match tree.sample(p, n, u) {
                    Some((i, pmf)) => {
                        let want = tree.pmf(p, n, i);
                        assert!((pmf - want).abs() <= 1e-5 * pmf, "light {i}: {pmf} vs {want}");
                        count[i] += 1;
                    }
                    None => count[lights.len()] += 1,
                }
            }
            for (i, &c) in count.iter().enumerate() {
                let chance = if i < lights.len() { tree.pmf(p, n, i) as f64 } else { 1.0 - total };
                let want = chance * draws as f64;
                assert!((c as f64 - want).abs() <= 5.0 * want.sqrt() + 3.0, "light {i}: {c} vs {want}");
            }
        }
    }

    /// A light that sends something to a point has a chance there; one
    /// facing away has none.
    #[test]
    fn importance_is_zero_only_where_nothing_arrives() {
        let lights = disks(200);
        let tree = LightSampler::new(&lights, 20.0);
        let mut rng = stream(5, Domain::Camera, 2);
        let (mut behind, mut skipped) = (0u32, 0u32);
        for _ in 0..2000 {
            let u = next_2d(&mut rng);
            let p = Vec3::new(u.x * 14.0 - 2.0, u.y * 14.0 - 2.0, next_2d(&mut rng).x * 6.0 - 3.0);
            let n = uniform_cone(next_2d(&mut rng), -1.0).normalize();
            for (i, l) in lights.iter().enumerate() {
                let chance = tree.pmf(p, n, i);
                if !l.faces_away(p) {
                    assert!(chance > 0.0, "light {i} at {p}");
                }
                behind += l.faces_away(p) as u32;
                skipped += (l.faces_away(p) && chance == 0.0) as u32;
            }
        }
        // Most lights seen from behind are never chosen (the rest are near
        // their plane, within their bounding sphere's angle).
        assert!(skipped as f32 > 0.7 * behind as f32, "{skipped} of {behind}");
    }
}
